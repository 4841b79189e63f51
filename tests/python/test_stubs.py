"""The type stubs (waam_slicer.pyi) describe the module as built: the same
classes, functions and public members."""

import ast
import types

import waam_slicer as ws
from conftest import REPO


def stub_names():
    tree = ast.parse((REPO / "waam_slicer.pyi").read_text())
    top, members = set(), {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            top.add(node.name)
            members[node.name] = {
                n.name for n in node.body if isinstance(n, ast.FunctionDef)
            }
        elif isinstance(node, ast.FunctionDef):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
    return top, members


def test_stubs_match_the_module():
    top, members = stub_names()
    public = {
        n for n in dir(ws)
        if not n.startswith("_") and not isinstance(getattr(ws, n), types.ModuleType)
    } | {"__version__"}
    assert top == public
    for cls, names in members.items():
        runtime = {n for n in vars(getattr(ws, cls)) if not n.startswith("_")}
        runtime |= {n for n in names if n.startswith("__") and hasattr(getattr(ws, cls), n)}
        assert names == runtime, cls
