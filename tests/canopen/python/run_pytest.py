"""Runs the python tests of `cia402 bus`, or skips (exit 77) saying why when python3-can or
python3-pytest is missing. Usage: run_pytest.py CIA402_BINARY [TEST_FILE.py ...] [pytest args]:
the named files of this folder, or every test file in it."""
import os
import sys

SKIP = 77
missing = []
for module, package in (("pytest", "python3-pytest"), ("can", "python3-can")):
    try:
        __import__(module)
    except ImportError:
        missing.append(package)
if missing:
    print("SKIPPED: the python tests need " + " and ".join(missing)
          + " (apt-get install " + " ".join(missing) + ")")
    sys.exit(SKIP)

import pytest  # noqa: E402

os.environ["CIA402_BIN"] = sys.argv[1]
here = os.path.dirname(os.path.abspath(__file__))
files = [os.path.join(here, a) for a in sys.argv[2:] if a.endswith(".py")]
rest = [a for a in sys.argv[2:] if not a.endswith(".py")]
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider"] + (files or [here]) + rest))
