"""Fixtures of the Python package's tests. CTest runs them (run_pytest.py) with PYTHONPATH set to
the build's python/ folder; CIA402_SOURCE_DIR, CIA402_BUILD_DIR and, when the tool is built,
CIA402_TOOL name the source tree, the build and the `cia402` program."""
import os
import pathlib

import pytest


@pytest.fixture(scope="session")
def source_dir() -> pathlib.Path:
    return pathlib.Path(os.environ.get("CIA402_SOURCE_DIR", pathlib.Path(__file__).parents[2]))


@pytest.fixture(scope="session")
def examples(source_dir) -> pathlib.Path:
    return source_dir / "examples"


@pytest.fixture(scope="session")
def tool() -> str:
    """The `cia402` program, to hold the package's answers against the command line's."""
    path = os.environ.get("CIA402_TOOL", "")
    if not path or not os.path.exists(path):
        pytest.skip("the cia402 tool is not built (CIA402_TOOL)")
    return path
