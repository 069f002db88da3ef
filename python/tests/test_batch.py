"""python -m dmc.batch on a 2-worker Dask LocalCluster: every sequence of ../shared/data (when
present; a synthetic set otherwise) plus a broken file, the manifest, resuming, and the streams
equal to the CLI's."""

import json
import os
import subprocess
import sys
import tempfile
import unittest

import dmc
import dmc.batch
import support

try:
    import distributed
except ImportError:  # python3-distributed (tools/install-deps.sh)
    distributed = None


def make_root(root):
    """Links to every sequence of the shared data (or synthetic ones), and one broken input."""
    if support.SHARED_DATA and os.path.isdir(support.SHARED_DATA):
        for entry in sorted(os.listdir(support.SHARED_DATA)):
            source = os.path.join(support.SHARED_DATA, entry)
            if os.path.isdir(source) and not entry.startswith(("_", ".")):
                os.symlink(source, os.path.join(root, entry))
    else:
        for name in ("cloth", "blob"):
            frames, faces = dmc.synth(name, frames=4, resolution=300)
            dmc.write_sequence(os.path.join(root, name, name + ".pc2"), frames, faces)
    broken = os.path.join(root, "broken")
    os.makedirs(broken)
    with open(os.path.join(broken, "1.obj"), "w", encoding="utf-8") as out:
        out.write("v 0 0 0\nv 1 0 0\nf 1 2 9\n")


@unittest.skipIf(distributed is None, "python3-distributed is not installed")
class BatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scratch = tempfile.TemporaryDirectory()
        cls.root = os.path.join(cls.scratch.name, "root")
        cls.out = os.path.join(cls.scratch.name, "out")
        os.makedirs(cls.root)
        make_root(cls.root)
        cls.first = cls.run_batch()

    @classmethod
    def tearDownClass(cls):
        cls.scratch.cleanup()

    @classmethod
    def run_batch(cls, *extra):
        return subprocess.run(
            [sys.executable, "-m", "dmc.batch", cls.root, "-o", cls.out, "--workers", "2", *extra],
            capture_output=True, text=True, check=False, cwd=cls.scratch.name)

    def manifest(self):
        with open(os.path.join(self.out, "manifest.jsonl"), encoding="utf-8") as manifest:
            return [json.loads(line) for line in manifest]

    def test_every_sequence_is_encoded_and_the_broken_one_recorded(self):
        self.assertEqual(self.first.returncode, 1, self.first.stdout + self.first.stderr)
        records = self.manifest()
        inputs = dmc.batch.find_sequences(self.root)
        self.assertEqual(sorted(r["input"] for r in records), inputs)
        self.assertGreaterEqual(len(inputs), 3)
        failed = [r for r in records if r["error"]]
        self.assertEqual([os.path.basename(r["input"]) for r in failed], ["broken"])
        self.assertEqual(failed[0]["error"]["code"], "parse-error")
        self.assertIn("1.obj:3", failed[0]["error"]["message"])
        for record in records:
            self.assertEqual(set(record), {"input", "output", "bytes", "bpfv", "kg", "sted",
                                           "seconds", "error"})
            if record["error"] is None:
                with self.subTest(input=record["input"]):
                    self.assertEqual(os.path.getsize(record["output"]), record["bytes"])
                    self.assertGreater(record["bpfv"], 0)
                    self.assertGreater(record["sted"], 0)
                    self.assertIsNotNone(record["kg"])
                    self.assertEqual(dmc.info(record["output"])["bytes"], record["bytes"])
        self.assertFalse([f for f in os.listdir(self.out) if f.endswith(".tmp")])

    def test_a_second_run_skips_what_is_done(self):
        before = {r["input"]: r for r in self.manifest()}
        again = self.run_batch()
        self.assertIn("dmc.batch: 1 to encode", again.stdout)  # only the broken input again
        after = {r["input"]: r for r in self.manifest()}
        self.assertEqual(set(before), set(after))
        for source, record in before.items():
            if record["error"] is None:
                self.assertEqual(after[source], record)

    @support.require_cli
    def test_streams_are_the_clis(self):
        caches = [r for r in self.manifest()
                  if r["error"] is None and r["input"].endswith(".pc2")]
        self.assertTrue(caches)
        record = caches[0]
        cli_stream = os.path.join(self.scratch.name, "cli.dmc")
        support.run_cli("encode", record["input"], "-o", cli_stream)
        with open(cli_stream, "rb") as a, open(record["output"], "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_bad_options_are_refused_before_any_work(self):
        result = subprocess.run(
            [sys.executable, "-m", "dmc.batch", self.root, "-o",
             os.path.join(self.scratch.name, "unused"), "--option", "residul_bits=3"],
            capture_output=True, text=True, check=False)
        self.assertEqual(result.returncode, 2)
        self.assertIn("residul_bits: not an encoder option", result.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.scratch.name, "unused")))


if __name__ == "__main__":
    unittest.main()
