"""dmc.edit and dmc.methods: the processing registry on NumPy arrays."""

import json
import os
import tempfile
import unittest

import numpy as np

import dmc
import support


def translation(offset):
    """Row-major 4x4 affine transform translating by `offset`, as a flat list."""
    matrix = np.eye(4)
    matrix[:3, 3] = offset
    return matrix.ravel().tolist()


class EditTest(unittest.TestCase):
    def setUp(self):
        self.frames, self.faces = support.small_animation(frames=3, resolution=300)
        self.vertices = self.frames.shape[1]
        self.handles = np.arange(0, 10)
        self.fixed = np.arange(self.vertices - 10, self.vertices)

    def test_registry_lists_laplacian_edit_and_its_parameters(self):
        table = {row["name"]: row for row in dmc.methods()}
        edit = table["laplacian-edit"]
        self.assertTrue(edit["needs_selection"])
        self.assertEqual(edit["scope"], "per-frame")
        keywords = {p["keyword"]: p for p in edit["parameters"]}
        self.assertIn("anchor_weight", keywords)
        self.assertEqual(keywords["anchor_weight"]["name"], "anchor-weight")

    def test_identity_transform_keeps_the_mesh(self):
        frames, faces = dmc.edit("laplacian-edit", self.frames, self.faces,
                                 selection={"handles": self.handles, "fixed": self.fixed})
        np.testing.assert_array_equal(faces, self.faces)
        np.testing.assert_allclose(frames, self.frames, atol=1e-5)

    def test_translating_the_only_constraints_translates_everything(self):
        # L annihilates constants: x + t keeps every differential coordinate and meets the hard
        # handle constraints, so it is the solution (one connected component).
        offset = [0.25, -0.5, 1.0]
        frames, _ = dmc.edit("laplacian-edit", self.frames, self.faces,
                             selection={"handles": self.handles.tolist(),
                                        "transform": translation(offset)})
        np.testing.assert_allclose(frames, self.frames + np.float32(offset), atol=1e-4)

    def test_handles_move_and_fixed_vertices_stay(self):
        offset = [0.0, 0.0, 0.3]
        frames, _ = dmc.edit("laplacian-edit", self.frames, self.faces,
                             selection={"handles": self.handles, "fixed": self.fixed,
                                        "transform": translation(offset)})
        np.testing.assert_allclose(frames[:, self.handles], self.frames[:, self.handles] + offset,
                                   atol=1e-6)
        np.testing.assert_allclose(frames[:, self.fixed], self.frames[:, self.fixed], atol=1e-6)
        moved = np.linalg.norm(frames - self.frames, axis=2)
        self.assertTrue(np.all(moved[:, 50:-50].max(axis=1) > 1e-4))  # the free part deforms

    def test_selection_forms_agree_and_one_mesh_stays_one_mesh(self):
        selection = {"handles": self.handles.tolist(), "fixed": self.fixed.tolist(),
                     "transform": translation([0.1, 0.0, 0.0])}
        expected, _ = dmc.edit("laplacian-edit", self.frames[0], self.faces, selection=selection)
        self.assertEqual(expected.shape, self.frames[0].shape)
        from_json, _ = dmc.edit("laplacian-edit", self.frames[0], self.faces,
                                selection=json.dumps(selection))
        np.testing.assert_array_equal(from_json, expected)
        with tempfile.TemporaryDirectory() as scratch:
            path = os.path.join(scratch, "selection.json")
            with open(path, "w") as out:
                json.dump(selection, out)
            from_file, _ = dmc.edit("laplacian-edit", self.frames[0], self.faces, selection=path)
        np.testing.assert_array_equal(from_file, expected)

    def test_parameters_reach_the_method(self):
        selection = {"handles": self.handles, "fixed": self.fixed,
                     "transform": translation([0.0, 0.2, 0.0])}
        hard, _ = dmc.edit("laplacian-edit", self.frames, self.faces, selection=selection)
        soft, _, details = dmc.edit("laplacian-edit", self.frames, self.faces,
                                    selection=selection, constraints="soft", weight=1.0,
                                    return_details=True)
        self.assertGreater(np.abs(hard - soft).max(), 1e-4)  # weak soft constraints give way
        self.assertIsInstance(details["measurements"], list)

    def test_errors(self):
        def code_of(call):
            with self.assertRaises(dmc.Error) as caught:
                call()
            return caught.exception.code

        selection = {"handles": self.handles}
        self.assertIs(code_of(lambda: dmc.edit("no-such-method", self.frames, self.faces)),
                      dmc.ErrorCode.NOT_FOUND)
        self.assertIs(code_of(lambda: dmc.edit("laplacian-edit", self.frames, self.faces,
                                               selection=selection, no_such_parameter=1)),
                      dmc.ErrorCode.NOT_FOUND)
        self.assertIs(code_of(lambda: dmc.edit("laplacian-edit", self.frames, self.faces,
                                               selection=selection, weight="heavy")),
                      dmc.ErrorCode.INVALID_ARGUMENT)
        self.assertIs(code_of(lambda: dmc.edit("laplacian-edit", self.frames, self.faces)),
                      dmc.ErrorCode.INVALID_ARGUMENT)  # a selection is required
        self.assertIs(code_of(lambda: dmc.edit("laplacian-edit", self.frames, self.faces,
                                               selection={"handles": [self.vertices]})),
                      dmc.ErrorCode.INVALID_ARGUMENT)
        self.assertIs(code_of(lambda: dmc.edit("laplacian-edit", self.frames, self.faces,
                                               selection={"handles": [1]}, weight=[1, 2])),
                      dmc.ErrorCode.INVALID_ARGUMENT)


@support.require_cli
class ParameterNamesTest(unittest.TestCase):
    """morph's own "frames" parameter is edit()'s frames argument too (issue 27): it goes in
    parameters={...}, and the keyword form says so instead of a bare TypeError."""

    def setUp(self):
        self.frames, self.faces = dmc.synth("cloth", frames=4, resolution=200)

    def test_a_colliding_parameter_goes_in_the_parameters_dict(self):
        for count in (2, 5, 9):
            out, _ = dmc.edit("morph", self.frames, self.faces, parameters={"frames": count})
            self.assertEqual(out.shape, (count,) + self.frames.shape[1:])
            # t = 0 and t = 1 are the source and target frames.
            np.testing.assert_allclose(out[0], self.frames[0], atol=1e-5)
            np.testing.assert_allclose(out[-1], self.frames[-1], atol=1e-5)
        # Keywords and the dict mix; one name twice is refused.
        out, _ = dmc.edit("morph", self.frames, self.faces, parameters={"frames": 3},
                          interpolation="linear")
        self.assertEqual(out.shape[0], 3)
        with self.assertRaises(dmc.InvalidArgumentError):
            dmc.edit("morph", self.frames, self.faces, parameters={"to": 2}, to=3)
        with self.assertRaises(dmc.InvalidArgumentError):
            dmc.edit("morph", self.frames, self.faces, parameters=[("frames", 3)])

    def test_the_keyword_form_points_to_the_dict(self):
        with self.assertRaisesRegex(TypeError, r"multiple values for argument 'frames'.*"
                                               r"parameters=\{'frames': \.\.\.\}"):
            dmc.edit("morph", self.frames, self.faces, frames=5)


class CliEqualityTest(unittest.TestCase):
    def test_edit_equals_the_cli(self):
        frames, faces = support.small_animation(frames=3, resolution=300)
        vertices = frames.shape[1]
        selection = {"handles": list(range(10)), "fixed": list(range(vertices - 10, vertices)),
                     "transform": translation([0.0, 0.1, 0.2])}
        with tempfile.TemporaryDirectory() as scratch:
            sequence = os.path.join(scratch, "input")
            dmc.write_sequence(sequence, frames, faces)
            selection_path = os.path.join(scratch, "selection.json")
            with open(selection_path, "w") as out:
                json.dump(selection, out)
            for params, flags in [({}, []), ({"constraints": "soft", "weight": 50.0},
                                             ["--constraints", "soft", "--weight", "50"])]:
                with self.subTest(params=params):
                    output = os.path.join(scratch, "edited")
                    support.run_cli("edit", "laplacian-edit", sequence, "-o", output,
                                    "--selection", selection_path, "--operator", "cotan", *flags)
                    cli_frames, _ = dmc.read_sequence(output)
                    ours, _ = dmc.edit("laplacian-edit", frames, faces, selection=selection,
                                       **params)
                    np.testing.assert_array_equal(ours, cli_frames)


if __name__ == "__main__":
    unittest.main()
