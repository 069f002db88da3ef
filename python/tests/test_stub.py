"""The committed type stub (python/dmc/_dmc.pyi) is what python/tools/make_stub.py makes of the
built module: regenerate it with that script when a signature changes."""

import ast
import importlib.util
import os
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
STUB = os.path.join(HERE, "..", "dmc", "_dmc.pyi")
MAKER = os.path.join(HERE, "..", "tools", "make_stub.py")


class StubTest(unittest.TestCase):
    def test_committed_stub_matches_the_module(self):
        spec = importlib.util.spec_from_file_location("make_stub", MAKER)
        maker = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(maker)
        with open(STUB, encoding="utf-8") as committed:
            self.assertEqual(committed.read(), maker.stub_text(),
                             "python/dmc/_dmc.pyi is stale: run python/tools/make_stub.py")

    def test_stub_is_valid_python_declaring_every_public_name(self):
        import dmc
        with open(STUB, encoding="utf-8") as committed:
            tree = ast.parse(committed.read())
        declared = {node.name for node in tree.body
                    if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
        declared |= {node.target.id for node in tree.body if isinstance(node, ast.AnnAssign)}
        self.assertEqual(set(dmc.__all__) - declared, set())
        self.assertTrue(os.path.exists(os.path.join(HERE, "..", "dmc", "py.typed")))


if __name__ == "__main__":
    unittest.main()
