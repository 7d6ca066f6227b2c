"""Runs the Python package's tests (this folder, or the files named) against a built package, or
skips (exit 77) saying why when python3-pytest is missing.

    run_pytest.py PACKAGE_DIR [pytest arguments: files, folders, options]

PACKAGE_DIR is the build's python/ folder (it holds cia402/); it goes first on PYTHONPATH, also
for the subprocesses the tests start."""
import os
import sys

SKIP = 77
try:
    import pytest
except ImportError:
    print("SKIPPED: the Python package's tests need python3-pytest (apt-get install python3-pytest)")
    sys.exit(SKIP)

package_dir = os.path.abspath(sys.argv[1])
os.environ["PYTHONPATH"] = os.pathsep.join([package_dir] + [p for p in [os.environ.get("PYTHONPATH")] if p])
sys.path.insert(0, package_dir)
here = os.path.dirname(os.path.abspath(__file__))
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", "--rootdir", here] + (sys.argv[2:] or [here])))
