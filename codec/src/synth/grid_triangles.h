// The triangulation of a rectangular vertex grid, the one copy used by the grid builders of the
// synthetic generators, the tests, the benchmarks, the fuzz targets and the conformance
// generator. Header-only so that a test linking one library can still use it.
#pragma once

#include "dmc/sequence.h"

namespace dmc::synth {

enum class GridDiagonals {
  kUniform,      // every cell split along the diagonal from (column, row) to (column+1, row+1)
  kAlternating,  // that diagonal where column + row is even, the other one elsewhere (a
                 // checkerboard: no preferred shear direction, valences 4 to 8)
};

// Two triangles per cell of a `columns` × `rows` vertex grid, vertex = row * columns + column,
// cells row by row, counter-clockwise seen from +z when rows grow along +y. columns, rows ≥ 2.
inline Triangles GridTriangles(int columns, int rows, GridDiagonals diagonals) {
  Triangles triangles(2 * (columns - 1) * (rows - 1), 3);
  int t = 0;
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < columns; ++c) {
      const int v00 = r * columns + c, v10 = v00 + 1;
      const int v01 = v00 + columns, v11 = v01 + 1;
      if (diagonals == GridDiagonals::kUniform || (r + c) % 2 == 0) {
        triangles.row(t++) << v00, v10, v11;
        triangles.row(t++) << v00, v11, v01;
      } else {
        triangles.row(t++) << v00, v10, v01;
        triangles.row(t++) << v10, v11, v01;
      }
    }
  }
  return triangles;
}

}  // namespace dmc::synth
