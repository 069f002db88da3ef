// The processing method registry: one row per method. Adding a method is one .cpp file in this
// directory defining `MethodInfo <Name>Method()` (name, description, scope, declared parameters,
// precompute; see dmc/processing.h) plus its declaration and row below.
#include <fmt/format.h>

#include <string>
#include <vector>

#include "dmc/processing.h"

namespace dmc {

// Each defined in the file named beside it.
MethodInfo LaplacianEditMethod();     // laplacian_edit.cpp
MethodInfo SmoothExplicitMethod();    // smoothing.cpp
MethodInfo SmoothTaubinMethod();      // smoothing.cpp
MethodInfo SmoothImplicitMethod();    // smoothing.cpp
MethodInfo ParamBarycentricMethod();  // param_barycentric.cpp
MethodInfo MorphMethod();             // morph.cpp
MethodInfo LeastSquaresMeshMethod();  // ls_mesh.cpp
MethodInfo CurvatureMethod();         // curvature.cpp
MethodInfo SpectralFilterMethod();    // spectral_filter.cpp
MethodInfo SpacetimeArapMethod();     // spacetime_arap.cpp

// The restricted B-spline methods, in bspline_spectrum.cpp and bspline_poisson_fit.cpp.
MethodInfo BsplineSpectrumMethod();
MethodInfo BsplinePoissonFitMethod();

namespace {

using MethodRow = MethodInfo (*)();

// The table, in the order `dmc edit --help` lists the methods.
const MethodRow kMethods[] = {
    LaplacianEditMethod,     // one row per line, so adding a method is a one-line change
    SmoothExplicitMethod,    //
    SmoothTaubinMethod,      //
    SmoothImplicitMethod,    //
    ParamBarycentricMethod,  //
    MorphMethod,             //
    LeastSquaresMeshMethod,  //
    CurvatureMethod,         //
    SpectralFilterMethod,    //
    SpacetimeArapMethod,     //

    BsplineSpectrumMethod,    //
    BsplinePoissonFitMethod,  //
};

const std::vector<MethodInfo>& Table() {
  static const std::vector<MethodInfo> table = [] {
    std::vector<MethodInfo> rows;
    for (MethodRow row : kMethods) rows.push_back(row());
    return rows;
  }();
  return table;
}

}  // namespace

std::span<const MethodInfo> ProcessingRegistry() { return Table(); }

StatusOr<const MethodInfo*> FindMethod(std::string_view name) {
  std::string known;
  for (const MethodInfo& info : Table()) {
    if (info.name == name) return &info;
    known += known.empty() ? "" : ", ";
    known += info.name;
  }
  return NotFoundError(
      fmt::format("unknown processing method '{}'; known methods: {}", name, known));
}

}  // namespace dmc
