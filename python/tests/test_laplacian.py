"""dmc.laplacian and dmc.operators: hand-computed matrices, identities, the CLI's statistics."""

import os
import sys
import tempfile
import unittest

import numpy as np
import scipy.sparse

import dmc
import support


def dense(matrix):
    return matrix.toarray() if scipy.sparse.issparse(matrix) else np.asarray(matrix)


def cotangent_weights(positions, faces):
    """Reference k_ij = (cot a + cot b) / 2 over the angles opposite each edge, as a dict."""
    p = positions.astype(np.float64)
    weights = {}
    for triangle in faces:
        for corner in range(3):
            o, i, j = triangle[corner], triangle[(corner + 1) % 3], triangle[(corner + 2) % 3]
            u, v = p[i] - p[o], p[j] - p[o]
            cot = np.dot(u, v) / np.linalg.norm(np.cross(u, v))
            key = (min(i, j), max(i, j))
            weights[key] = weights.get(key, 0.0) + cot / 2.0
    return weights


class HandComputedTest(unittest.TestCase):
    def test_kirchhoff_and_tutte_on_a_tetrahedron(self):
        positions, faces = support.tetrahedron()
        adjacency = np.ones((4, 4)) - np.eye(4)  # every pair is an edge
        kirchhoff = dmc.laplacian(positions, faces, "kirchhoff")
        self.assertIsInstance(kirchhoff, scipy.sparse.csr_matrix)
        np.testing.assert_array_equal(dense(kirchhoff), adjacency - 3 * np.eye(4))
        np.testing.assert_allclose(dense(dmc.laplacian(positions, faces, "tutte")),
                                   adjacency / 3 - np.eye(4), rtol=0, atol=1e-15)

    def test_cotangent_operators_on_the_unit_square(self):
        # Triangles (0,1,2) and (0,2,3): the boundary edges face one 45 degree angle each
        # (k = cot 45 / 2 = 1/2); the diagonal 0-2 faces two right angles (k = 0, stored).
        positions, faces = support.unit_square()
        k = 0.5
        expected = np.array([[-2 * k, k, 0, k], [k, -2 * k, k, 0], [0, k, -2 * k, k],
                             [k, 0, k, -2 * k]])
        cotan_sym, mass = dmc.laplacian(positions, faces, "cotan-sym", return_mass=True)
        np.testing.assert_allclose(dense(cotan_sym), expected, rtol=0, atol=1e-15)
        self.assertEqual(cotan_sym.nnz, 4 + 2 * 5)  # diagonal plus both directions of 5 edges
        # Mixed Voronoi areas of two right isosceles triangles: the hypotenuse corners get 1/8
        # per triangle, the right-angle corners 1/4; they add up to the area, 1.
        np.testing.assert_allclose(mass, [0.25, 0.25, 0.25, 0.25], rtol=1e-14)
        cotan_area = dmc.laplacian(positions, faces, "cotan-area")
        np.testing.assert_allclose(dense(cotan_area), np.diag(1 / mass) @ expected, rtol=1e-14)
        self.assertIsNone(dmc.laplacian(positions, faces, "tutte", return_mass=True)[1])

    def test_cotan_sym_equals_the_formula_on_a_curved_mesh(self):
        frames, faces = support.small_animation(frames=1, name="blob", resolution=200)
        matrix = dmc.laplacian(frames[0], faces, "cotan-sym").tocoo()
        weights = cotangent_weights(frames[0], faces)
        for i, j, value in zip(matrix.row, matrix.col, matrix.data):
            if i != j:
                self.assertAlmostEqual(value, weights[(min(i, j), max(i, j))], delta=1e-12)


class PropertiesTest(unittest.TestCase):
    def setUp(self):
        self.frames, self.faces = support.small_animation(frames=5, resolution=300)

    def test_every_operator_has_zero_row_sums(self):
        for row in dmc.operators():
            if row["domain"] != "vertex":
                continue  # spacetime (V·F × V·F) and bspline (elements) act on other domains
            with self.subTest(operator=row["name"]):
                matrix = dmc.laplacian(self.frames, self.faces, row["name"])
                self.assertEqual(matrix.shape, (self.frames.shape[1],) * 2)
                sums = np.abs(np.asarray(matrix.sum(axis=1))).max()
                scale = np.abs(matrix.diagonal()).max()
                self.assertLess(sums, 1e-10 * scale)
                if row["symmetric"]:
                    self.assertEqual(abs(matrix - matrix.T).max(), 0.0)
                if row["unit_sum"]:
                    np.testing.assert_allclose(matrix.diagonal(), -1.0, rtol=1e-12)

    def test_registry_rows(self):
        table = {row["name"]: row for row in dmc.operators()}
        self.assertEqual(table["kirchhoff"]["wire_id"], 1)
        self.assertEqual(table["tutte"]["wire_id"], 2)
        self.assertEqual(table["ddl"]["wire_id"], 7)
        self.assertTrue(table["ddl"]["needs_trajectories"])
        self.assertTrue(table["cotan"]["needs_geometry"])
        self.assertEqual(table["cotan"]["domain"], "vertex")
        self.assertEqual(table["spacetime"]["domain"], "spacetime")
        self.assertEqual(table["bspline"]["domain"], "element")
        self.assertIsNone(table["spacetime"]["wire_id"])

    def test_other_domains_are_refused_with_a_clear_error(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.laplacian(self.frames, self.faces, "bspline")
        self.assertIn("bspline", str(caught.exception))

    def test_triple_without_scipy(self):
        expected = dmc.laplacian(self.frames, self.faces, "cotan")
        saved = {name: sys.modules.get(name) for name in ("scipy", "scipy.sparse")}
        try:
            sys.modules["scipy"] = None  # makes `import scipy.sparse` raise ImportError
            sys.modules["scipy.sparse"] = None
            data, indices, indptr = dmc.laplacian(self.frames, self.faces, "cotan")
        finally:
            for name, module in saved.items():
                sys.modules[name] = module
        self.assertEqual(indices.dtype, np.int32)
        np.testing.assert_array_equal(data, expected.data)
        np.testing.assert_array_equal(indices, expected.indices)
        np.testing.assert_array_equal(indptr, expected.indptr)

    def test_bad_arguments(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.laplacian(self.frames, self.faces, "no-such-operator")
        self.assertIs(caught.exception.code, dmc.ErrorCode.NOT_FOUND)
        self.assertIn("cotan-area", caught.exception.message)
        for params in ({"reference": "kirchhoff"}, {"reference_frame": 5}, {"rank": -1},
                       {"mu": -1.0}, {"mu": float("nan")}):
            with self.subTest(params=params), self.assertRaises(dmc.Error) as caught:
                dmc.laplacian(self.frames, self.faces, "ddl", **params)
            self.assertIs(caught.exception.code, dmc.ErrorCode.INVALID_ARGUMENT)


def cli_statistics(matrix, frames):
    """The matrix statistics `dmc laplacian --json` prints, computed here from `matrix`."""
    entries = matrix.tocoo()
    off_diagonal = entries.data[entries.row != entries.col]  # explicit zeros included, as there
    trajectories = frames.astype(np.float64).transpose(1, 0, 2).reshape(frames.shape[1], -1)
    delta = (matrix @ trajectories).reshape(frames.shape[1], frames.shape[0], 3)
    norms = np.linalg.norm(delta, axis=2)
    return {
        "max_row_sum": np.abs(np.asarray(matrix.sum(axis=1))).max(),
        "diagonal_min": matrix.diagonal().min(),
        "diagonal_max": matrix.diagonal().max(),
        "negative_weight_share": np.count_nonzero(off_diagonal < 0) / off_diagonal.size,
        "symmetry_error": abs(matrix.T - matrix).max() / abs(matrix).max(),
        "delta_mean": norms.mean(),
        "delta_max": norms.max(),
    }


@support.require_cli
class CliEqualityTest(unittest.TestCase):
    """The Python matrix reproduces every statistic `dmc laplacian` reports on its own matrix."""

    def test_statistics_equal_the_cli(self):
        frames, faces = support.small_animation(frames=6, name="twist", resolution=300)
        cases = [("cotan", {}, []), ("mean-value", {"reference_frame": 2},
                                     ["--reference-frame", "2"]),
                 ("kirchhoff", {}, []), ("ddl", {"mu": 0.02}, ["--mu", "0.02"]),
                 ("ddl-asym", {"rank": 4}, ["--rank", "4"])]
        with tempfile.TemporaryDirectory() as scratch:
            sequence = os.path.join(scratch, "twist")
            dmc.write_sequence(sequence, frames, faces)
            for name, params, flags in cases:
                with self.subTest(operator=name):
                    cli = support.run_cli_json("laplacian", sequence, "--operator", name, *flags)
                    ours = cli_statistics(dmc.laplacian(frames, faces, name, **params), frames)
                    for key, value in ours.items():
                        self.assertAlmostEqual(value, cli[key], delta=1e-12 * max(1.0, abs(value)),
                                               msg=key)


if __name__ == "__main__":
    unittest.main()
