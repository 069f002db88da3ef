"""The package as Python code sees it: real signatures, error classes under the right built-ins,
TypeErrors that describe arguments instead of printing them, and read_sequence's metadata passed
on to encode."""

import inspect
import os
import tempfile
import unittest

import numpy as np

import dmc
import support

PUBLIC_FUNCTIONS = ["decode", "edit", "encode", "encoder_options", "info", "laplacian", "methods",
                    "metrics", "operators", "read_sequence", "set_simd_variant", "simd_variant",
                    "simd_variants", "synth", "synth_names", "write_sequence"]


class SignatureTest(unittest.TestCase):
    def test_every_function_has_a_signature(self):
        for name in PUBLIC_FUNCTIONS:
            with self.subTest(name=name):
                signature = inspect.signature(getattr(dmc, name))
                self.assertIsInstance(signature, inspect.Signature)
                self.assertIn(name, dmc.__all__)

    def test_encode_lists_every_encoder_option_with_its_default(self):
        parameters = inspect.signature(dmc.encode).parameters
        self.assertEqual(list(parameters)[:2], ["frames", "faces"])
        for option in dmc.encoder_options():
            with self.subTest(option=option["name"]):
                parameter = parameters[option["name"]]
                self.assertIs(parameter.kind, inspect.Parameter.KEYWORD_ONLY)
                self.assertEqual(parameter.default, option["default"])

    def test_defaults_in_the_signature_are_the_defaults_used(self):
        # Calling with every default spelled out gives what calling without them gives.
        frames, faces = dmc.synth("cloth", frames=3, resolution=200)
        for function, args in [(dmc.metrics, (frames, frames[::-1].copy(), faces)),
                               (dmc.synth, ("blob",)),
                               (dmc.decode, (dmc.encode(frames, faces),))]:
            with self.subTest(function=function.__name__):
                defaults = {p.name: p.default
                            for p in inspect.signature(function).parameters.values()
                            if p.default is not inspect.Parameter.empty}
                self.assertTrue(defaults)
                plain, spelled = function(*args), function(*args, **defaults)
                if isinstance(plain, dict):
                    self.assertEqual(plain, spelled)
                else:
                    for a, b in zip(plain, spelled):
                        np.testing.assert_array_equal(a, b)

    def test_help_shows_the_parameters(self):
        self.assertIn("max_output_bytes=4294967296", str(inspect.signature(dmc.decode)))
        self.assertTrue(dmc.decode.__doc__.startswith("decode(data, *, max_output_bytes="))


class ErrorClassesTest(unittest.TestCase):
    def test_errors_derive_from_the_matching_built_ins(self):
        positions, faces = support.tetrahedron()
        with self.assertRaises(ValueError) as bad_argument:
            dmc.encode(positions, faces, residual_bits=-3)
        self.assertIsInstance(bad_argument.exception, dmc.InvalidArgumentError)
        self.assertIsInstance(bad_argument.exception, dmc.Error)
        with self.assertRaises(OSError) as missing:
            dmc.read_sequence(os.path.join(tempfile.gettempdir(), "no-such-dir", "x.obj"))
        self.assertIsInstance(missing.exception, dmc.IoError)
        self.assertIs(missing.exception.code, dmc.ErrorCode.IO_ERROR)
        self.assertIsNone(missing.exception.errno)  # not the error code taken for an errno
        with self.assertRaises(LookupError):
            dmc.synth("no-such-generator")
        with self.assertRaises(ValueError) as corrupt:
            dmc.decode(b"DMC?")
        self.assertIsInstance(corrupt.exception, dmc.StreamError)

    def test_every_code_has_a_class_that_round_trips(self):
        import pickle
        for code in dmc.ErrorCode:
            if code == dmc.ErrorCode.OK:
                continue
            with self.subTest(code=code.name):
                error = dmc.Error(code, "what")
                self.assertIsNot(type(error), dmc.Error)
                again = pickle.loads(pickle.dumps(error))
                self.assertIs(type(again), type(error))
                self.assertIs(again.code, code)
                self.assertEqual(str(again), f"{error.code_name}: what")


class TypeErrorTest(unittest.TestCase):
    def setUp(self):
        self.frames, self.faces = dmc.synth("cloth", frames=3, resolution=200)

    def test_a_misspelt_keyword_gets_a_suggestion(self):
        with self.assertRaisesRegex(TypeError, "'residul_bits' \\(did you mean 'residual_bits'\\?\\)"):
            dmc.encode(self.frames, self.faces, residul_bits=8)
        with self.assertRaisesRegex(TypeError, "'sted_widht' \\(did you mean 'sted_width'\\?\\)"):
            dmc.metrics(self.frames, self.frames, self.faces, sted_widht=2)

    def test_arrays_are_described_not_printed(self):
        with self.assertRaises(TypeError) as caught:
            dmc.encode(self.frames, self.faces, self.frames)
        message = str(caught.exception)
        self.assertIn("ndarray float32 (3, ", message)
        self.assertNotIn("e-0", message)  # no array values
        self.assertLess(len(message), 2000)


class MetadataIdiomTest(unittest.TestCase):
    def test_read_sequence_metadata_goes_straight_to_encode(self):
        with tempfile.TemporaryDirectory() as directory:
            frames, faces = dmc.synth("cloth", frames=3, resolution=200)
            path = os.path.join(directory, "flag")
            dmc.write_sequence(path, frames, faces)  # OBJ frames: no frame rate recorded
            frames, faces, metadata = dmc.read_sequence(path, metadata=True)
            self.assertIsNone(metadata["frame_rate"])
            stream = dmc.encode(frames, faces, name=metadata["name"],
                                frame_rate=metadata["frame_rate"])
            info = dmc.info(stream)
            self.assertEqual(info["name"], "flag")
            self.assertIsNone(info["frame_rate"])


if __name__ == "__main__":
    unittest.main()
