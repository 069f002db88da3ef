"""dmc.read_sequence / dmc.write_sequence / dmc.synth."""

import os
import pathlib
import tempfile
import unittest

import numpy as np

import dmc
import support


class ReadWriteTest(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory()
        self.frames, self.faces = support.small_animation(frames=4)
        # Values whose shortest decimal form is long, to catch any lossy formatting.
        self.frames = (self.frames * np.float32(1 / 3)).astype(np.float32)

    def tearDown(self):
        self.scratch.cleanup()

    def path(self, name):
        return os.path.join(self.scratch.name, name)

    def test_round_trip_is_bit_exact_in_every_format(self):
        for target, frame_format in [("obj_dir", "obj"), ("off_dir", "off"), ("ply_dir", "ply"),
                                     ("cache.pc2", "obj")]:
            with self.subTest(target=target):
                dmc.write_sequence(self.path(target), self.frames, self.faces,
                                   frame_format=frame_format)
                frames, faces = dmc.read_sequence(self.path(target))
                np.testing.assert_array_equal(frames, self.frames)
                np.testing.assert_array_equal(faces, self.faces)

    def test_single_mesh_file_and_pathlib(self):
        target = pathlib.Path(self.path("one.ply"))
        dmc.write_sequence(target, self.frames[0], self.faces)
        frames, faces = dmc.read_sequence(target)
        self.assertEqual(frames.shape, (1,) + self.frames.shape[1:])
        np.testing.assert_array_equal(frames[0], self.frames[0])
        with self.assertRaises(dmc.Error):  # one mesh file holds exactly one frame
            dmc.write_sequence(self.path("many.obj"), self.frames, self.faces)

    def test_metadata_and_max_frames(self):
        dmc.write_sequence(self.path("walk"), self.frames, self.faces, frame_rate=24.0)
        frames, faces, meta = dmc.read_sequence(self.path("walk"), max_frames=2, threads=1,
                                                metadata=True)
        self.assertEqual(frames.shape[0], 2)
        self.assertEqual(meta, {"name": "walk", "frame_rate": 24.0, "warnings": [],
                                "vertex_map": []})
        glob_frames, _ = dmc.read_sequence(os.path.join(self.path("walk"), "frame_000[13].obj"))
        np.testing.assert_array_equal(glob_frames, self.frames[[1, 3]])

    def test_quads_are_fan_triangulated_with_a_warning(self):
        with open(self.path("quad.obj"), "w") as mesh:
            mesh.write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
        frames, faces, meta = dmc.read_sequence(self.path("quad.obj"), metadata=True)
        np.testing.assert_array_equal(faces, [[0, 1, 2], [0, 2, 3]])
        self.assertEqual(len(meta["warnings"]), 1)
        self.assertIsNone(meta["frame_rate"])

    def test_errors_name_the_file(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.read_sequence(self.path("missing_dir"))
        self.assertIs(caught.exception.code, dmc.ErrorCode.IO_ERROR)
        with open(self.path("bad.obj"), "w") as mesh:
            mesh.write("v 0 0 0\nv 1 0\n")
        with self.assertRaises(dmc.Error) as caught:
            dmc.read_sequence(self.path("bad.obj"))
        self.assertIs(caught.exception.code, dmc.ErrorCode.PARSE_ERROR)
        self.assertIn("bad.obj:2", caught.exception.message)
        with self.assertRaises(dmc.Error) as caught:
            dmc.write_sequence(self.path("no/such/parent/out"), self.frames, self.faces)
        self.assertIs(caught.exception.code, dmc.ErrorCode.IO_ERROR)
        with self.assertRaises(dmc.Error) as caught:
            dmc.write_sequence(self.path("out"), self.frames, self.faces, frame_format="stl")
        self.assertIs(caught.exception.code, dmc.ErrorCode.INVALID_ARGUMENT)

    @unittest.skipUnless(os.path.isdir(os.path.join(support.SHARED_DATA, "cow")),
                         "../shared/data is absent")
    def test_reads_a_real_sequence(self):
        frames, faces = dmc.read_sequence(os.path.join(support.SHARED_DATA, "cow"), max_frames=3)
        self.assertEqual(frames.shape, (3, 2904, 3))
        self.assertEqual(faces.shape, (5804, 3))

    @unittest.skipUnless(os.path.isfile(os.path.join(support.SHARED_DATA, "fox", "Fox.glb")),
                         "../shared/data is absent")
    def test_gltf_options(self):
        fox = os.path.join(support.SHARED_DATA, "fox", "Fox.glb")
        # The Fox's clips by name and index, sampled at 10 fps (the CLI tests' counts).
        walk, _ = dmc.read_sequence(fox, gltf_fps=10, gltf_animation="Walk")
        run, _ = dmc.read_sequence(fox, gltf_fps=10, gltf_animation="2")
        self.assertEqual(walk.shape[0], 8)
        self.assertEqual(run.shape[0], 12)
        # Welding merges the seam-split vertices and keeps the map from file vertices.
        plain, faces, info = dmc.read_sequence(fox, gltf_fps=2, metadata=True)
        welded, welded_faces, welded_info = dmc.read_sequence(fox, gltf_fps=2, gltf_weld=True,
                                                              metadata=True)
        self.assertEqual(plain.shape[1], 1728)
        self.assertEqual(welded.shape[1], 290)
        self.assertEqual(welded_faces.shape, faces.shape)
        self.assertEqual(len(welded_info["vertex_map"]), 1728)
        self.assertEqual(max(welded_info["vertex_map"]), 289)
        np.testing.assert_array_equal(welded[:, welded_info["vertex_map"], :], plain)
        with self.assertRaises(dmc.Error) as caught:
            dmc.read_sequence(fox, gltf_mesh="Nobody")
        self.assertIn("Nobody", str(caught.exception))
        with self.assertRaises(dmc.Error):
            dmc.read_sequence(fox, gltf_fps=-1)


class SynthTest(unittest.TestCase):
    def test_generators_are_deterministic_and_seeded(self):
        self.assertEqual(dmc.synth_names(), ["twist", "cloth", "walker", "blob"])
        first, faces = dmc.synth("walker", frames=3, resolution=600)
        again, faces_again = dmc.synth("walker", frames=3, resolution=600)
        np.testing.assert_array_equal(first, again)
        np.testing.assert_array_equal(faces, faces_again)
        other_seed, other_faces = dmc.synth("walker", frames=3, resolution=600, seed=2)
        np.testing.assert_array_equal(other_faces, faces)
        self.assertFalse(np.array_equal(other_seed, first))
        # A shorter sequence is a prefix of a longer one.
        longer, _ = dmc.synth("walker", frames=5, resolution=600)
        np.testing.assert_array_equal(longer[:3], first)

    def test_bad_options(self):
        with self.assertRaises(dmc.Error) as caught:
            dmc.synth("cloth", frames=0)
        self.assertIs(caught.exception.code, dmc.ErrorCode.INVALID_ARGUMENT)


if __name__ == "__main__":
    unittest.main()
