"""What the tests of the tree checks share (check_layers_test.py, check_sizes_test.py): a check run
on a small tree written to a temporary folder, and the report of the named checks."""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def run_check(script, exceptions_file, files, exceptions=""):
    """Runs scripts/<script> on a tree of `files` (path: text) whose scripts/<exceptions_file>
    holds `exceptions`; returns its exit code and standard output."""
    with tempfile.TemporaryDirectory() as root:
        for path, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
            with open(os.path.join(root, path), "w", encoding="utf-8") as f:
                f.write(text)
        os.makedirs(os.path.join(root, "scripts"), exist_ok=True)
        with open(os.path.join(root, "scripts", exceptions_file), "w", encoding="utf-8") as f:
            f.write(exceptions)
        r = subprocess.run([sys.executable, os.path.join(HERE, script), root], capture_output=True, text=True)
        return r.returncode, r.stdout


def report(checks):
    """Prints each (name, passed) check and a count; returns the exit code: 1 if any failed."""
    failed = [name for name, ok in checks if not ok]
    for name, ok in checks:
        print(("ok   " if ok else "FAIL ") + name)
    print(f"{len(checks) - len(failed)} passed, {len(failed)} failed")
    return 1 if failed else 0
