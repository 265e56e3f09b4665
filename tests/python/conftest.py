"""Shared fixtures of the Python tests: the repository root and the saltus program (set by ctest)."""
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
