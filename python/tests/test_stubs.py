"""The hand-written type hints (slamrig/_core.pyi) name exactly what the C++ core defines."""

import ast
import os

from slamrig import _core

STUB = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                    "slamrig", "_core.pyi")


def _stub():
    """Top-level classes and functions of the stub, each class with its public members."""
    tree = ast.parse(open(STUB, encoding="utf-8").read())
    classes, functions = {}, set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            functions.add(node.name)
        elif isinstance(node, ast.ClassDef):
            if any(getattr(b, "id", None) == "Protocol" for b in node.bases):
                continue  # what Python code provides, not part of the core
            members = set()
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
                elif isinstance(item, ast.Assign):
                    members.update(t.id for t in item.targets if isinstance(t, ast.Name))
            classes[node.name] = members
    return classes, functions


def _public(names):
    return {n for n in names if not n.startswith("_")}


def test_stub_names_every_class_and_function_of_the_core():
    classes, functions = _stub()
    core = _public(dir(_core))
    assert set(classes) | functions == core


def test_stub_names_every_public_member_of_each_class():
    classes, _ = _stub()
    for name, members in classes.items():
        cls = getattr(_core, name)
        if issubclass(cls, Exception):
            continue
        defined = _public(vars(cls))
        if hasattr(cls, "__members__"):  # a pybind11 enum: its values and name/value
            defined -= {"name", "value"}
        assert _public(members) == defined, name
