"""dmc.Error and dmc.ErrorCode: pinned codes, messages, and refusal of bad shapes and dtypes."""

import os
import pickle
import tempfile
import unittest

import numpy as np

import dmc
import support

# The frozen values of dmc::ErrorCode (codec/include/dmc/status.h, wire_ids.h).
PINNED_CODES = {
    "OK": 0, "INVALID_ARGUMENT": 1, "IO_ERROR": 2, "PARSE_ERROR": 3, "INVALID_SEQUENCE": 4,
    "MISMATCH": 5, "UNSUPPORTED": 6, "CORRUPT_STREAM": 7, "TRUNCATED_STREAM": 8,
    "NUMERICAL_FAILURE": 9, "NOT_FOUND": 10, "INTERNAL": 11, "RESOURCE_LIMIT": 12,
}


class ErrorClassTest(unittest.TestCase):
    def test_codes_are_the_pinned_values(self):
        self.assertEqual({code.name: int(code) for code in dmc.ErrorCode}, PINNED_CODES)

    def test_error_carries_code_name_and_message(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.synth("no-such-generator")
        error = caught.exception
        self.assertIsInstance(error, Exception)
        self.assertIs(error.code, dmc.ErrorCode.NOT_FOUND)
        self.assertEqual(error.code, 10)
        self.assertEqual(error.code_name, "not-found")
        self.assertIn("no-such-generator", error.message)
        self.assertEqual(str(error), "not-found: " + error.message)

    def test_error_pickles(self):
        error = pickle.loads(pickle.dumps(dmc.Error(dmc.ErrorCode.MISMATCH, "frame 3 differs")))
        self.assertIs(error.code, dmc.ErrorCode.MISMATCH)
        self.assertEqual(str(error), "mismatch: frame 3 differs")


class BadInputTest(unittest.TestCase):
    def setUp(self):
        self.positions, self.faces = support.tetrahedron()

    def assert_error(self, code, call, *fragments):
        """Asserts that `call()` raises dmc.Error with `code` and a message holding `fragments`."""
        with self.assertRaises(dmc.Error) as caught:
            call()
        self.assertIs(caught.exception.code, code, caught.exception)
        for fragment in fragments:
            self.assertIn(fragment, caught.exception.message)
        return caught.exception

    def test_frames_of_wrong_shape_are_refused_naming_the_shape(self):
        invalid = dmc.ErrorCode.INVALID_ARGUMENT
        for shape in [(4, 2), (2, 4, 4), (12,), (1, 1, 4, 3)]:
            with self.subTest(shape=shape):
                shape_text = str(shape)
                self.assert_error(invalid, lambda: dmc.encode(np.zeros(shape, np.float32),
                                                              self.faces),
                                  "frames must have shape (F, V, 3)", f"got shape {shape_text}")

    def test_faces_of_wrong_shape_or_dtype_are_refused(self):
        invalid = dmc.ErrorCode.INVALID_ARGUMENT
        self.assert_error(invalid, lambda: dmc.encode(self.positions, self.faces[:, :2]),
                          "faces must have shape (T, 3)", "got shape (4, 2)")
        self.assert_error(invalid, lambda: dmc.encode(self.positions, self.faces.ravel()),
                          "got shape (12,)")
        self.assert_error(invalid,
                          lambda: dmc.encode(self.positions, self.faces.astype(np.float64)),
                          "faces must hold integers", "float64")

    def test_non_numeric_frames_are_refused(self):
        invalid = dmc.ErrorCode.INVALID_ARGUMENT
        self.assert_error(invalid,
                          lambda: dmc.encode(self.positions.astype(np.complex64), self.faces),
                          "real numbers", "complex64")
        self.assert_error(invalid, lambda: dmc.encode([["a", "b", "c"]] * 4, self.faces),
                          "real numbers")
        self.assert_error(invalid, lambda: dmc.encode([[0, 0, 0], [1, 0]], self.faces),
                          "cannot be converted")

    def test_indices_beyond_int32_are_refused_not_wrapped(self):
        faces = self.faces.astype(np.int64)
        faces[1, 2] = 2**32 + 1  # would wrap to 1, a valid index
        self.assert_error(dmc.ErrorCode.INVALID_ARGUMENT,
                          lambda: dmc.encode(self.positions, faces), "faces[1, 2]",
                          "does not fit int32")

    def test_model_violations_name_the_element(self):
        bad_sequence = dmc.ErrorCode.INVALID_SEQUENCE
        faces = self.faces.copy()
        faces[2, 1] = 4
        self.assert_error(bad_sequence, lambda: dmc.encode(self.positions, faces))
        positions = self.positions.copy()
        positions[2, 1] = np.nan
        self.assert_error(bad_sequence, lambda: dmc.encode(positions, self.faces), "vertex 2")
        huge = self.positions.astype(np.float64)
        huge[3, 0] = 1e300  # beyond float32: converts to infinity, refused as non-finite
        with np.errstate(over="ignore"):  # NumPy's own warning about the cast
            self.assert_error(bad_sequence, lambda: dmc.encode(huge, self.faces), "vertex 3")
        self.assert_error(bad_sequence,
                          lambda: dmc.encode(self.positions, np.zeros((0, 3), np.int32)))

    def test_options_are_checked_by_the_library(self):
        # The library's messages name the option, which is the keyword.
        self.assert_error(dmc.ErrorCode.INVALID_ARGUMENT,
                          lambda: dmc.encode(self.positions, self.faces, basis_bits=40),
                          "basis_bits must be in [2, 16], got 40")
        self.assert_error(dmc.ErrorCode.INVALID_ARGUMENT,
                          lambda: dmc.encode(self.positions, self.faces, ddl_mu=-1.0),
                          "ddl_mu must be >= 0")
        self.assert_error(dmc.ErrorCode.INVALID_ARGUMENT,
                          lambda: dmc.encode(self.positions, self.faces, target_bpfv=2.0,
                                             target_sted=0.01),
                          "give target_bpfv or target_sted, not both")
        error = self.assert_error(dmc.ErrorCode.NOT_FOUND,
                                  lambda: dmc.encode(self.positions, self.faces,
                                                     operator="nope"))
        self.assertIn("tutte", error.message)  # the message lists the names that exist
        with self.assertRaisesRegex(TypeError, "rank must be int, got <class 'str'>"):
            dmc.encode(self.positions, self.faces, rank="three")
        with self.assertRaisesRegex(TypeError, "name must be str"):
            dmc.encode(self.positions, self.faces, name=3)
        with self.assertRaisesRegex(TypeError, "unexpected keyword argument 'ddl_regularization'"):
            dmc.encode(self.positions, self.faces, ddl_regularization=0.1)

    def test_damaged_streams_raise_stream_codes(self):
        frames, faces = support.small_animation()
        stream = dmc.encode(frames, faces)
        damaged = bytearray(stream)
        damaged[len(damaged) // 2] ^= 0x40
        self.assert_error(dmc.ErrorCode.CORRUPT_STREAM, lambda: dmc.decode(bytes(damaged)))
        truncated = self.assert_error_in(
            (dmc.ErrorCode.TRUNCATED_STREAM, dmc.ErrorCode.CORRUPT_STREAM),
            lambda: dmc.decode(stream[: len(stream) // 2]))
        self.assertTrue(truncated.message)
        self.assert_error(dmc.ErrorCode.INVALID_ARGUMENT, lambda: dmc.decode(12345),
                          "bytes-like")
        with tempfile.TemporaryDirectory() as scratch:
            self.assert_error(dmc.ErrorCode.IO_ERROR,
                              lambda: dmc.decode(os.path.join(scratch, "missing.dmc")))

    def test_output_above_the_limit_is_a_resource_limit(self):
        frames, faces = support.small_animation()
        stream = dmc.encode(frames, faces)
        output_bytes = 12 * (frames.shape[0] * frames.shape[1] + faces.shape[0])
        self.assert_error(dmc.ErrorCode.RESOURCE_LIMIT,
                          lambda: dmc.decode(stream, max_output_bytes=output_bytes - 1),
                          "above the limit")
        decoded, _ = dmc.decode(stream, max_output_bytes=output_bytes)
        self.assertEqual(decoded.shape, frames.shape)
        self.assertEqual(dmc.decode(stream, max_output_bytes=0)[0].shape, frames.shape)
        self.assert_error(dmc.ErrorCode.RESOURCE_LIMIT,
                          lambda: dmc.decode(stream, max_matrix_bytes=64), "normal matrix")
        self.assertEqual(dmc.decode(stream, max_matrix_bytes=0)[0].shape, frames.shape)

    def assert_error_in(self, codes, call):
        with self.assertRaises(dmc.Error) as caught:
            call()
        self.assertIn(caught.exception.code, codes)
        return caught.exception


if __name__ == "__main__":
    unittest.main()
