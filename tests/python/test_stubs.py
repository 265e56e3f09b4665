"""The type stubs (python/saltus/__init__.pyi) name exactly what the module exports, and every
function and class of the module has a docstring."""
import ast
import inspect
import pathlib
import subprocess
import sys

import saltus

STUBS = pathlib.Path(saltus.__file__).with_name("__init__.pyi")


def public_names():
    return {n for n in dir(saltus._saltus) if not n.startswith("_")}


def test_the_stubs_name_every_export():
    tree = ast.parse(STUBS.read_text())
    stubbed = {node.name for node in tree.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    assert stubbed == public_names()


def test_every_export_has_a_docstring():
    for name in public_names():
        obj = getattr(saltus, name)
        if inspect.isroutine(obj) or inspect.isclass(obj):
            assert (obj.__doc__ or "").strip(), name


def test_the_figure_example_runs(tmp_path, root):
    out = tmp_path / "drop.png"
    subprocess.run([sys.executable, str(root / "examples/python/drop_figure.py"), str(out)], check=True,
                   env={"PYTHONPATH": str(pathlib.Path(saltus.__file__).parents[1]), "MPLBACKEND": "Agg"})
    assert out.stat().st_size > 10000
