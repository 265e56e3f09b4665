"""Shared fixtures of the Python tests: the repository root and the saltus program (set by ctest)."""
import importlib.util
import os
import pathlib

import pytest

ROOT = pathlib.Path(os.environ.get("SALTUS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture
def root():
    return ROOT


@pytest.fixture
def saltus_binary():
    path = os.environ.get("SALTUS_BINARY")
    if not path:
        pytest.fail("SALTUS_BINARY is not set (ctest sets it to the built saltus program)")
    return path


def example(name):
    """A script of examples/python as a module (its functions, without running its main)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / "python" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
