"""Runs the python tests of `cia402 bus`, or skips (exit 77) saying why when python3-can or
python3-pytest is missing. Usage: run_pytest.py CIA402_BINARY [pytest args]."""
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
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", here] + sys.argv[2:]))
