"""`cmake --install` puts the package where Debian's python3 finds it, and it imports from there."""
import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest


def test_an_install_into_a_prefix_imports_with_its_stubs(tmp_path):
    build = os.environ.get("CIA402_BUILD_DIR")
    if not build or shutil.which("cmake") is None:
        pytest.skip("needs CIA402_BUILD_DIR and cmake")
    cache = pathlib.Path(build, "CMakeCache.txt").read_text()
    folder = re.search(r"^CIA402_PYTHON_INSTALL_DIR:STRING=(.*)$", cache, re.M).group(1)
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    package = prefix / folder / "cia402"
    assert {"__init__.py", "__init__.pyi", "sim.py", "sim.pyi", "_errors.py", "py.typed"} <= {
        p.name for p in package.iterdir()}
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(prefix / folder)
    out = subprocess.run(
        [sys.executable, "-c", "import cia402; print(cia402.__file__); print(cia402.__version__); "
                               "print(cia402.Drive().settle().state)"],
        capture_output=True, text=True, env=env, check=True, cwd=tmp_path).stdout.split()
    assert out[0].startswith(str(package)) and out[2] == "SWITCH_ON_DISABLED"


def test_the_install_folder_is_one_debians_python3_searches():
    cache = pathlib.Path(os.environ.get("CIA402_BUILD_DIR", "."), "CMakeCache.txt")
    if not cache.exists():
        pytest.skip("needs CIA402_BUILD_DIR")
    text = cache.read_text()
    prefix = re.search(r"^CMAKE_INSTALL_PREFIX:PATH=(.*)$", text, re.M).group(1)
    folder = re.search(r"^CIA402_PYTHON_INSTALL_DIR:STRING=(.*)$", text, re.M).group(1)
    debian = "/usr/bin/python3"
    if not os.path.exists(debian):
        pytest.skip("no Debian python3")
    path = subprocess.run([debian, "-c", "import sys; print('\\n'.join(sys.path))"],
                          capture_output=True, text=True, check=True).stdout.split()
    assert os.path.join(prefix, folder) in path
