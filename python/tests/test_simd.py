"""dmc.simd_variants / simd_variant / set_simd_variant and DMC_SIMD: every variant the CPU runs
decodes the same frames; bad names raise the pinned error codes."""

import os
import subprocess
import sys
import unittest

import numpy as np

import dmc
import support


class SimdVariantTest(unittest.TestCase):
    def tearDown(self):
        dmc.set_simd_variant("auto")

    def test_every_variant_decodes_the_same_frames(self):
        frames, faces = support.small_animation()
        stream = dmc.encode(frames, faces, residual_bits=12)
        variants = dmc.simd_variants()
        self.assertEqual(variants[-1], "baseline")
        decoded = {}
        for variant in variants:
            dmc.set_simd_variant(variant)
            self.assertEqual(dmc.simd_variant(), variant)
            decoded[variant] = dmc.decode(stream)[0]
        for variant in variants:
            np.testing.assert_array_equal(decoded[variant], decoded["baseline"], err_msg=variant)
        dmc.set_simd_variant("auto")
        self.assertEqual(dmc.simd_variant(), variants[0])

    def test_unknown_and_unavailable_names_raise(self):
        with self.assertRaises(dmc.Error) as raised:
            dmc.set_simd_variant("avx3")
        self.assertEqual(raised.exception.code, dmc.ErrorCode.INVALID_ARGUMENT)
        missing = [name for name in ("avx512", "avx2", "sse4", "ssse3", "neon")
                   if name not in dmc.simd_variants()]
        for name in missing:
            with self.assertRaises(dmc.Error) as raised:
                dmc.set_simd_variant(name)
            self.assertEqual(raised.exception.code, dmc.ErrorCode.UNSUPPORTED)

    def test_environment_variable_sets_the_variant_at_import(self):
        probe = "import dmc; print(dmc.simd_variant())"
        env = dict(os.environ, DMC_SIMD="baseline")
        result = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                                text=True, check=True)
        self.assertEqual(result.stdout.strip(), "baseline")
        env["DMC_SIMD"] = "no-such-variant"
        result = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True,
                                text=True, check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("DMC_SIMD", result.stderr)


if __name__ == "__main__":
    unittest.main()
