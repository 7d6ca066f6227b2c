"""The type stubs (__init__.pyi, sim.pyi, canopen.pyi, ethercat.pyi) name exactly what the package has: every public
function and class, and every public method and property of each class. mypy is not a Debian
default, so the stubs are checked by parsing them against the module itself."""
import ast
import inspect
import pathlib

import pytest

import cia402
from cia402 import canopen, ethercat, sim

PACKAGE = pathlib.Path(cia402.__file__).parent


def stub(name):
    return ast.parse((PACKAGE / name).read_text(), filename=name)


def top_level_names(tree):
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.ImportFrom) and node.module != "typing" and node.module != "os":
            names.update(alias.asname for alias in node.names if alias.asname)
    return names


def classes(tree):
    return {node.name: node for node in tree.body if isinstance(node, ast.ClassDef)}


def members(node):
    names = set()
    for item in node.body:
        if isinstance(item, ast.FunctionDef):
            names.add(item.name)
        elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
            names.add(item.target.id)
        elif isinstance(item, ast.Assign):  # a method declared as another's alias (settle = step)
            names.update(t.id for t in item.targets if isinstance(t, ast.Name))
    return names


@pytest.mark.parametrize("module, file", [(cia402, "__init__.pyi"), (sim, "sim.pyi"), (canopen, "canopen.pyi"), (ethercat, "ethercat.pyi")])
def test_the_stub_names_every_public_name_of_the_module(module, file):
    assert (PACKAGE / "py.typed").exists()
    assert top_level_names(stub(file)) == set(module.__all__)


@pytest.mark.parametrize("module, file", [(cia402, "__init__.pyi"), (sim, "sim.pyi"), (canopen, "canopen.pyi"), (ethercat, "ethercat.pyi")])
def test_each_stub_class_has_exactly_the_real_classes_members(module, file):
    for name, node in classes(stub(file)).items():
        real = getattr(module, name)
        declared = members(node)
        public = {m for m in dir(real) if not m.startswith("_")}
        assert {m for m in declared if not m.startswith("_")} == public, name
        for dunder in declared - {"__init__"}:
            if dunder.startswith("__"):
                assert hasattr(real, dunder), (name, dunder)


def test_every_public_class_and_function_has_a_docstring():
    for module in (cia402, sim, canopen, ethercat):
        for name in module.__all__:
            value = getattr(module, name)
            if inspect.isclass(value) or callable(value):
                assert (value.__doc__ or "").strip(), f"{module.__name__}.{name}"
