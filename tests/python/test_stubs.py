"""The type stubs (python/saltus/__init__.pyi) describe the module as built: the same functions and
classes, each function and method with the parameters of the compiled one (names, order, which are
keyword-only), each class with the same methods and properties; and every export has a docstring."""
import ast
import inspect
import pathlib
import subprocess
import sys

import saltus

STUBS = pathlib.Path(saltus.__file__).with_name("__init__.pyi")


def public_names():
    return {n for n in dir(saltus._saltus) if not n.startswith("_")}


def split_top_level(text):
    """Splits "a: int, b: Dict[str, float] = {}" at the commas outside brackets."""
    parts, depth, start = [], 0, 0
    for i, c in enumerate(text):
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def compiled_parameters(obj):
    """Parameter names of a pybind11 function from its signature line ('*' marks keyword-only)."""
    line = obj.__doc__.splitlines()[0]
    inside = line[line.index("(") + 1:line.rindex(") ->")]
    names = [p.split(":")[0].split("=")[0].strip() for p in split_top_level(inside)]
    return [n for n in names if n != "self"]


def stub_parameters(node):
    args = node.args
    names = [a.arg for a in args.posonlyargs + args.args]
    if args.kwonlyargs:
        names += ["*"] + [a.arg for a in args.kwonlyargs]
    return [n for n in names if n != "self"]


def stub_tree():
    return ast.parse(STUBS.read_text())


def test_the_stubs_name_every_export():
    stubbed = {node.name for node in stub_tree().body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    assert stubbed == public_names()


def test_the_stubs_give_each_function_its_compiled_parameters():
    checked = 0
    for node in stub_tree().body:
        if isinstance(node, ast.FunctionDef):
            assert stub_parameters(node) == compiled_parameters(getattr(saltus, node.name)), node.name
            checked += 1
    assert checked >= 15


def test_the_stubs_give_each_class_its_methods_and_properties():
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef) or node.name.endswith("Error"):
            continue
        cls = getattr(saltus, node.name)
        methods = {n.name: n for n in node.body if isinstance(n, ast.FunctionDef)}
        attributes = {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        # A class without a constructor from Python (made by the module only) has pybind11's
        # refusing __init__, which is not part of its interface.
        constructible = (cls.__init__.__doc__ or "").startswith("__init__(")
        compiled = {name: value for name, value in vars(cls).items()
                    if not name.startswith("_") or (name == "__init__" and constructible)}
        compiled_properties = {n for n, v in compiled.items() if isinstance(v, property)}
        compiled_methods = {n for n in compiled if n not in compiled_properties}
        assert attributes == compiled_properties, node.name
        assert set(methods) == compiled_methods, node.name
        for name, method in methods.items():
            assert stub_parameters(method) == compiled_parameters(getattr(cls, name)), f"{node.name}.{name}"


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
