"""dmc.encode / dmc.decode / dmc.info: round trips, equality with the CLI's bytes, input kinds."""

import os
import pathlib
import subprocess
import tempfile
import threading
import time
import unittest

import numpy as np

import dmc
import support


class RoundTripTest(unittest.TestCase):
    def setUp(self):
        self.frames, self.faces = support.small_animation()

    def test_decode_restores_shape_connectivity_and_close_positions(self):
        stream = dmc.encode(self.frames, self.faces, residual_bits=12)
        self.assertIsInstance(stream, bytes)
        frames, faces = dmc.decode(stream)
        self.assertEqual(frames.dtype, np.float32)
        self.assertEqual(faces.dtype, np.int32)
        self.assertEqual(frames.shape, self.frames.shape)
        # Vertex order is the input's; triangle order and rotation are the connectivity coder's.
        np.testing.assert_array_equal(support.canonical_triangles(faces),
                                      support.canonical_triangles(self.faces))
        # Residual step = diagonal * 2^-12: every vertex lands within a few steps of the input
        # (the δ quantisation error spreads through the operator's inverse, so "a few" is not 1:
        # 7.5 steps with the fitted DDL, 9.9 with the tutte coding the fallback picks here).
        diagonal = np.linalg.norm(self.frames.reshape(-1, 3).max(0) - self.frames.reshape(-1, 3).min(0))
        self.assertLess(np.abs(frames - self.frames).max(), 16 * diagonal * 2.0**-12)

    def test_report_matches_stream_and_measures_distortion(self):
        stream, report = dmc.encode(self.frames, self.faces, return_report=True)
        self.assertEqual(report["bytes"], len(stream))
        f, v = self.frames.shape[:2]
        self.assertAlmostEqual(report["bpfv"], 8.0 * len(stream) / (f * v), places=12)
        self.assertEqual(sum(report["breakdown"].values()), len(stream))
        decoded, _ = dmc.decode(stream)
        measured = dmc.metrics(self.frames, decoded, self.faces)
        for key in ("kg", "sted", "rmse_rel", "max_error"):
            self.assertEqual(report[key], measured[key], key)
        _, unmeasured = dmc.encode(self.frames, self.faces, return_report=True, measure=False)
        self.assertIsNone(unmeasured["kg"])

    def test_info_describes_the_stream(self):
        stream = dmc.encode(self.frames, self.faces, operator="tutte", rank=3, name="flag",
                            frame_rate=25.0)
        info = dmc.info(stream)
        self.assertEqual(info["vertices"], self.frames.shape[1])
        self.assertEqual(info["frames"], self.frames.shape[0])
        self.assertEqual(info["triangles"], self.faces.shape[0])
        self.assertEqual(info["name"], "flag")
        self.assertEqual(info["frame_rate"], 25.0)
        self.assertEqual(info["bytes"], len(stream))
        self.assertFalse(info["reordered"])
        self.assertEqual([s["operator"] for s in info["segments"]], ["tutte"])
        self.assertEqual(info["segments"][0]["rank"], 3)
        self.assertIsNone(dmc.info(dmc.encode(self.frames, self.faces))["frame_rate"])

    def test_every_bytes_like_input_and_paths_decode_alike(self):
        stream = dmc.encode(self.frames, self.faces)
        expected, expected_faces = dmc.decode(stream)
        with tempfile.TemporaryDirectory() as scratch:
            path = pathlib.Path(scratch) / "s.dmc"
            path.write_bytes(stream)
            inputs = [bytearray(stream), memoryview(stream), np.frombuffer(stream, np.uint8),
                      str(path), path]
            for data in inputs:
                frames, faces = dmc.decode(data)
                np.testing.assert_array_equal(frames, expected, err_msg=type(data).__name__)
                np.testing.assert_array_equal(faces, expected_faces)
            self.assertEqual(dmc.info(path), dmc.info(stream))

    def test_float64_and_strided_input_encode_like_float32(self):
        reference = dmc.encode(self.frames, self.faces)
        self.assertEqual(dmc.encode(self.frames.astype(np.float64), self.faces), reference)
        self.assertEqual(dmc.encode(self.frames, self.faces.astype(np.int64)), reference)
        self.assertEqual(dmc.encode(self.frames.tolist(), self.faces.tolist()), reference)
        # A Fortran-ordered copy and a strided view hold the same values in another layout.
        self.assertEqual(dmc.encode(np.asfortranarray(self.frames), self.faces), reference)
        doubled = np.repeat(self.frames, 2, axis=2)[:, :, ::2]
        self.assertFalse(doubled.flags.c_contiguous)
        self.assertEqual(dmc.encode(doubled, self.faces), reference)

    def test_one_frame_array_is_a_one_frame_sequence(self):
        frames, faces = dmc.decode(dmc.encode(self.frames[0], self.faces))
        self.assertEqual(frames.shape, (1,) + self.frames.shape[1:])

    def test_decoded_arrays_are_independent_and_writable(self):
        stream = dmc.encode(self.frames, self.faces)
        first, _ = dmc.decode(stream)
        second, _ = dmc.decode(stream)
        first[:] = 0
        self.assertTrue(np.any(second != 0))


class GilTest(unittest.TestCase):
    def test_encode_lets_other_threads_run(self):
        frames, faces = support.small_animation(frames=30, resolution=5000)
        ticks = 0
        worker = threading.Thread(target=dmc.encode, args=(frames, faces))
        start = time.perf_counter()
        worker.start()
        while worker.is_alive():
            ticks += 1
            time.sleep(0.001)
        worker.join()
        elapsed = time.perf_counter() - start
        if elapsed < 0.03:
            self.skipTest(f"the encode took {elapsed:.3f} s: too short to tell")
        # Were the GIL held through the C++ call, this loop could not run while the worker
        # works: a tick or two before the call starts, none during it. Released, it ticks
        # about once per millisecond.
        self.assertGreaterEqual(ticks, 10, f"{ticks} ticks during a {elapsed:.3f} s encode")

    def test_concurrent_encodes_give_identical_bytes(self):
        frames, faces = support.small_animation()
        expected = dmc.encode(frames, faces)
        results = [None] * 4

        def run(index):
            results[index] = dmc.encode(frames, faces)

        threads = [threading.Thread(target=run, args=(i,)) for i in range(len(results))]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        self.assertEqual(results, [expected] * len(results))


class OptionTableTest(unittest.TestCase):
    """dmc.encoder_options() is the table dmc.encode()'s keywords and `dmc encode`'s flags come
    from."""

    def setUp(self):
        self.options = dmc.encoder_options()

    def test_one_name_per_option_and_the_flag_is_the_name_with_dashes(self):
        names = [option["name"] for option in self.options]
        self.assertEqual(len(names), len(set(names)))
        for option in self.options:
            self.assertEqual(option["flag"], "--" + option["name"].replace("_", "-"))
            self.assertIn(option["type"], {"int", "float", "bool", "str"})
            self.assertIsInstance(option["default"], {"int": int, "float": float, "bool": bool,
                                                      "str": str}[option["type"]])
        self.assertIn("ddl_mu", names)
        self.assertIn("uniform_weight_prediction", names)
        self.assertFalse({"name", "frame_rate", "return_report"} & set(names))
        self.assertEqual([o["name"] for o in self.options if not o["shapes_stream"]], ["measure"])

    def test_every_option_is_a_keyword_taking_its_default(self):
        frames, faces = support.small_animation()
        defaults = {option["name"]: option["default"] for option in self.options}
        self.assertEqual(dmc.encode(frames, faces, **defaults), dmc.encode(frames, faces))
        self.assertIn("ddl_mu=0.1", dmc.encode.__doc__)
        for option in self.options:
            self.assertIn(f"    {option['name']}: ", dmc.encode.__doc__)

    @support.require_cli
    def test_every_option_is_a_cli_flag(self):
        help_text = support.run_cli("encode", "--help")
        for option in self.options:
            self.assertIn(option["flag"], help_text)
            if option["type"] == "bool":
                self.assertIn("--no-" + option["flag"][2:], help_text)


class EffortTest(unittest.TestCase):
    """effort= is EncoderOptions::effort: every level round-trips, a bad level or a switch the level
    would not honour is an error naming the keyword, and the report says which level ran."""

    def setUp(self):
        self.frames, self.faces = support.small_animation()

    def test_every_level_round_trips_and_is_reported(self):
        for effort in range(10):
            stream, report = dmc.encode(self.frames, self.faces, effort=effort, return_report=True)
            self.assertEqual(report["effort"], effort)
            frames, _ = dmc.decode(stream)
            self.assertEqual(frames.shape, self.frames.shape)
        self.assertEqual(dmc.encode(self.frames, self.faces),
                         dmc.encode(self.frames, self.faces, effort=2))

    def test_out_of_range_is_refused(self):
        for effort in (-1, 10):
            with self.assertRaisesRegex(dmc.Error, r"effort must be in \[0, 9\]"):
                dmc.encode(self.frames, self.faces, effort=effort)

    def test_a_switch_the_level_does_not_do_is_refused_not_ignored(self):
        with self.assertRaisesRegex(dmc.Error, "rank_search asks for a search that effort 1"):
            dmc.encode(self.frames, self.faces, effort=1, rank_search=True)
        with self.assertRaisesRegex(dmc.Error, "ddl_fallback asks for a search that effort 0"):
            dmc.encode(self.frames, self.faces, effort=0, ddl_fallback=True)
        # Named False it restricts any level; effort 0 is then the same one pass.
        self.assertEqual(dmc.encode(self.frames, self.faces, effort=0, rank_search=False,
                                    ddl_fallback=False),
                         dmc.encode(self.frames, self.faces, effort=0))
        self.assertEqual(dmc.encode(self.frames, self.faces, effort=9, ddl_fallback=False),
                         dmc.encode(self.frames, self.faces, effort=0))


@support.require_cli
class CliEqualityTest(unittest.TestCase):
    """Python and `dmc encode` give byte-identical streams for the same sequence and options."""

    OPTION_SETS = [
        {},
        {"operator": "tutte", "rank": 4, "residual_bits": 8, "basis_bits": 9, "anchors": 12},
        {"operator": "cotan", "segment_frames": 4, "reference_bits": 9, "anchor_step_ratio": 2.0},
        {"operator": "ddl", "weight_bits": 6, "ddl_mu": 0.05, "uniform_weight_prediction": True,
         "allow_reorder": True, "rank_threshold": 5.0},
        {"ddl_fallback": False, "residual_bits": 9},
        {"ddl_dead_zone": 0.0, "weight_bits": 5, "residual_step": 0.01, "rank_search": False},
        {"effort": 0},
        {"effort": 8, "residual_bits": 11},
    ]

    @classmethod
    def setUpClass(cls):
        cls.scratch = tempfile.TemporaryDirectory()
        cls.frames, cls.faces = support.small_animation(frames=9, name="twist")
        cls.input = os.path.join(cls.scratch.name, "twisty")
        dmc.write_sequence(cls.input, cls.frames, cls.faces, frame_rate=30.0)

    @classmethod
    def tearDownClass(cls):
        cls.scratch.cleanup()

    @staticmethod
    def cli_arguments(options):
        arguments = []
        for key, value in options.items():
            flag = "--" + key.replace("_", "-")
            if value is True:
                arguments.append(flag)
            elif value is False:  # every switch is also --no-<name>: --no-rank-search
                arguments.append("--no-" + key.replace("_", "-"))
            else:
                arguments += [flag, str(value)]
        return arguments

    def test_encode_bytes_equal_cli_bytes(self):
        frames, faces, meta = dmc.read_sequence(self.input, metadata=True)
        self.assertEqual(meta["name"], "twisty")
        for index, options in enumerate(self.OPTION_SETS):
            with self.subTest(options=options):
                output = os.path.join(self.scratch.name, f"cli{index}.dmc")
                support.run_cli("encode", self.input, "-o", output, "--no-measure",
                                *self.cli_arguments(options))
                with open(output, "rb") as stream:
                    cli_bytes = stream.read()
                ours = dmc.encode(frames, faces, name=meta["name"],
                                  frame_rate=meta["frame_rate"], **options)
                self.assertEqual(ours, cli_bytes)

    def test_rank_search_keyword_is_the_cli_switch(self):
        # On this blob at 10 bits the rank search picks a lower rank (a different stream), so
        # the keyword is seen to act, and rank_search=False is `--no-rank-search`.
        frames, faces = support.small_animation(frames=16, resolution=1500, name="blob")
        path = os.path.join(self.scratch.name, "blob16")
        dmc.write_sequence(path, frames, faces, frame_rate=30.0)
        frames, faces, meta = dmc.read_sequence(path, metadata=True)
        stream_meta = {"name": meta["name"], "frame_rate": meta["frame_rate"]}
        searched = dmc.encode(frames, faces, residual_bits=10, **stream_meta)
        plain = dmc.encode(frames, faces, residual_bits=10, rank_search=False, **stream_meta)
        self.assertNotEqual(searched, plain)
        output = os.path.join(self.scratch.name, "blob16.dmc")
        support.run_cli("encode", path, "-o", output, "--no-measure", "--residual-bits", "10",
                        "--no-rank-search")
        with open(output, "rb") as stream:
            self.assertEqual(plain, stream.read())
        self.assertLess(dmc.info(searched)["segments"][0]["rank"],
                        dmc.info(plain)["segments"][0]["rank"])

    def test_cli_refuses_a_switch_the_effort_does_not_do_as_python_does(self):
        output = os.path.join(self.scratch.name, "refused.dmc")
        result = subprocess.run([support.CLI, "encode", self.input, "-o", output, "--effort", "1",
                                 "--rank-search"], capture_output=True, text=True, check=False)
        self.assertNotEqual(result.returncode, 0)
        self.assertIn("--rank-search asks for a search that --effort 1 does not do", result.stderr)
        self.assertFalse(os.path.exists(output))
        with self.assertRaisesRegex(dmc.Error, "rank_search asks for a search that effort 1"):
            dmc.encode(self.frames, self.faces, effort=1, rank_search=True)

    def test_decode_equals_cli_decode(self):
        stream_path = os.path.join(self.scratch.name, "decode.dmc")
        support.run_cli("encode", self.input, "-o", stream_path, "--no-measure")
        decoded_dir = os.path.join(self.scratch.name, "decoded")
        support.run_cli("decode", stream_path, "-o", decoded_dir)
        cli_frames, cli_faces = dmc.read_sequence(decoded_dir)
        frames, faces = dmc.decode(stream_path)
        np.testing.assert_array_equal(frames, cli_frames)
        np.testing.assert_array_equal(faces, cli_faces)

    def test_report_equals_cli_json(self):
        output = os.path.join(self.scratch.name, "report.dmc")
        cli = support.run_cli_json("encode", self.input, "-o", output)
        frames, faces, meta = dmc.read_sequence(self.input, metadata=True)
        _, report = dmc.encode(frames, faces, name=meta["name"], frame_rate=meta["frame_rate"],
                               return_report=True)
        for key in ("bytes", "bpfv", "breakdown", "rank", "anchors", "segments", "residual_step",
                    "effort", "kg", "sted", "sted_s", "sted_t", "rmse_rel", "max_error"):
            self.assertEqual(report[key], cli[key], key)

    def test_info_equals_cli_info(self):
        output = os.path.join(self.scratch.name, "info.dmc")
        support.run_cli("encode", self.input, "-o", output, "--no-measure")
        cli = support.run_cli_json("info", output)
        del cli["input"]
        self.assertEqual(dmc.info(output), cli)


if __name__ == "__main__":
    unittest.main()
