"""Helpers shared by the dmc Python tests: tiny hand-made meshes and access to the dmc CLI.

The tests run under ctest (python/CMakeLists.txt) with PYTHONPATH pointing at the built module and
DMC_CLI at the built `dmc` binary (absent when the tools are not built: those tests skip).
"""

import json
import os
import subprocess
import unittest

import numpy as np

import dmc

CLI = os.environ.get("DMC_CLI", "")
SHARED_DATA = os.environ.get("DMC_SHARED_DATA_DIR", "")


def require_cli(test):
    """Skips `test` (a unittest.TestCase method or class) when the dmc binary is not available."""
    return unittest.skipUnless(CLI and os.path.exists(CLI), "the dmc CLI is not built")(test)


def run_cli(*args):
    """Runs `dmc ARGS...` and returns its stdout; fails the test with stderr on a non-zero exit."""
    result = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise AssertionError(f"dmc {' '.join(map(str, args))} exited with {result.returncode}:\n"
                             f"{result.stderr}")
    return result.stdout


def run_cli_json(*args):
    """Runs `dmc ARGS... --json` and returns the parsed document."""
    return json.loads(run_cli(*args, "--json"))


def unit_square():
    """Two triangles forming the unit square in z = 0, split along the diagonal 0-2.

    Vertices 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1); counter-clockwise triangles (0,1,2), (0,2,3).
    Returns (positions float32 (4, 3), faces int32 (2, 3)).
    """
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float32)
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    return positions, faces


def tetrahedron():
    """The corner tetrahedron (origin and the three unit points), outward-oriented faces."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    faces = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], dtype=np.int32)
    return positions, faces


def canonical_triangles(faces):
    """`faces` as a sorted array of oriented triangles, each rotated to start at its smallest
    index: equal for two triangle lists that hold the same oriented triangles in any order and
    rotation (as the codec's connectivity coding returns them)."""
    faces = np.asarray(faces)
    rotation = np.argmin(faces, axis=1)
    columns = (rotation[:, None] + np.arange(3)[None, :]) % 3
    rotated = np.take_along_axis(faces, columns, axis=1)
    return rotated[np.lexsort(rotated.T[::-1])]


def small_animation(frames=6, resolution=300, name="cloth", seed=1):
    """A small built-in animation (dmc.synth): (frames float32 (F, V, 3), faces int32 (T, 3))."""
    return dmc.synth(name, frames=frames, resolution=resolution, seed=seed)
