"""dmc.metrics: hand-computed values, identities, and equality with `dmc metrics`."""

import os
import tempfile
import unittest

import numpy as np

import dmc
import support


class MetricsTest(unittest.TestCase):
    def setUp(self):
        self.original, self.faces = support.small_animation(frames=7, name="blob", resolution=500)
        rng = np.random.default_rng(7)
        noise = rng.normal(scale=1e-3, size=self.original.shape)
        self.distorted = (self.original + noise).astype(np.float32)

    def test_identical_sequences_have_zero_distortion(self):
        result = dmc.metrics(self.original, self.original, self.faces)
        for key in ("kg", "sted", "sted_s", "sted_t", "rmse_rel", "max_error"):
            self.assertEqual(result[key], 0.0, key)
        self.assertEqual(result["frames"], self.original.shape[0])
        self.assertEqual(result["vertices"], self.original.shape[1])

    def test_kg_rmse_and_max_error_match_their_definitions(self):
        a = self.original.astype(np.float64)
        b = self.distorted.astype(np.float64)
        centred = a - a.mean(axis=1, keepdims=True)  # E(A): each frame's centroid
        kg = 100.0 * np.linalg.norm(a - b) / np.linalg.norm(centred)
        errors = np.linalg.norm(a - b, axis=2)
        flat = a.reshape(-1, 3)
        diagonal = np.linalg.norm(flat.max(axis=0) - flat.min(axis=0))
        rmse_rel = np.sqrt(np.mean(errors**2)) / diagonal
        result = dmc.metrics(self.original, self.distorted, self.faces)
        self.assertAlmostEqual(result["kg"] / kg, 1.0, delta=1e-12)
        self.assertAlmostEqual(result["rmse_rel"] / rmse_rel, 1.0, delta=1e-12)
        self.assertEqual(result["max_error"], errors.max())

    def test_uniform_scaling_has_no_spatial_sted(self):
        # Doubling every coordinate is exact in float32 and doubles every edge length, so every
        # relative edge difference is exactly -1: no deviation anywhere.
        result = dmc.metrics(self.original, 2.0 * self.original, self.faces)
        self.assertEqual(result["sted_s"], 0.0)
        self.assertGreater(result["sted_t"], 0.0)

    def test_one_frame_has_no_temporal_sted(self):
        result = dmc.metrics(self.original[0], self.distorted[0], self.faces)
        self.assertEqual(result["sted_t"], 0.0)
        self.assertEqual(result["frames"], 1)
        self.assertAlmostEqual(result["sted"], result["sted_s"], delta=0.0)

    def test_sted_options_are_passed_and_checked(self):
        default = dmc.metrics(self.original, self.distorted, self.faces)
        wider = dmc.metrics(self.original, self.distorted, self.faces, sted_width=2)
        self.assertNotEqual(wider["sted_s"], default["sted_s"])
        no_time = dmc.metrics(self.original, self.distorted, self.faces, sted_c=0.0)
        self.assertEqual(no_time["sted"], no_time["sted_s"])
        with self.assertRaises(dmc.Error) as caught:
            dmc.metrics(self.original, self.distorted, self.faces, sted_window=0)
        self.assertIs(caught.exception.code, dmc.ErrorCode.INVALID_ARGUMENT)

    def test_mismatched_sequences_are_refused(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.metrics(self.original, self.distorted[:-1], self.faces)
        self.assertIs(caught.exception.code, dmc.ErrorCode.MISMATCH)
        with self.assertRaises(dmc.Error) as caught:
            dmc.metrics(self.original, self.distorted[:, :-1], self.faces)
        self.assertIn(caught.exception.code,
                      (dmc.ErrorCode.MISMATCH, dmc.ErrorCode.INVALID_SEQUENCE))

    @support.require_cli
    def test_values_equal_the_cli(self):
        with tempfile.TemporaryDirectory() as scratch:
            original = os.path.join(scratch, "original")
            distorted = os.path.join(scratch, "distorted")
            dmc.write_sequence(original, self.original, self.faces)
            dmc.write_sequence(distorted, self.distorted, self.faces)
            for options, flags in [({}, []),
                                   ({"sted_width": 0, "sted_window": 3, "sted_dt": 0.001,
                                     "sted_c": 1e-4},
                                    ["--sted-width", "0", "--sted-window", "3", "--sted-dt",
                                     "0.001", "--sted-c", "0.0001"])]:
                cli = support.run_cli_json("metrics", original, distorted, *flags)
                ours = dmc.metrics(self.original, self.distorted, self.faces, **options)
                self.assertEqual(ours, cli)


if __name__ == "__main__":
    unittest.main()
