// Discrete Laplace operators on a fixed-connectivity mesh, all of them: an umbrella over the
// headers per concern, for code that uses several. Include the narrow one where one is enough:
// clang-format off
//   dmc/laplace_operator.h   the operator (matrix, weights, domain), assembly, sign convention
//   dmc/operator_formulas.h  geometric and combinatorial weights, builders, RebuildOperator
//   dmc/sparse_solvers.h     normal equations, SparseSpdSolver, AnchoredLaplacianSolver
//   dmc/operator_options.h   options of every operator family, OperatorSource
//   dmc/ddl_fit.h            data-dependent Laplacian fits (dmc_fitting)
//   dmc/operator_registry.h  the registry: OperatorInfo, FindOperator, BuildOperator
// clang-format on
#pragma once

#include "dmc/ddl_fit.h"
#include "dmc/laplace_operator.h"
#include "dmc/operator_formulas.h"
#include "dmc/operator_options.h"
#include "dmc/operator_registry.h"
#include "dmc/sparse_solvers.h"
