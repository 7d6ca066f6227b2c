#!/usr/bin/env python3
"""The layer check fails on an upward include, on a private include and on a stale exception, and
passes a tree that keeps the rules."""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def run(files, exceptions=""):
    with tempfile.TemporaryDirectory() as root:
        for path, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
            with open(os.path.join(root, path), "w", encoding="utf-8") as f:
                f.write(text)
        os.makedirs(os.path.join(root, "scripts"), exist_ok=True)
        with open(os.path.join(root, "scripts", "layer_exceptions.txt"), "w", encoding="utf-8") as f:
            f.write(exceptions)
        r = subprocess.run([sys.executable, os.path.join(HERE, "check_layers.py"), root],
                           capture_output=True, text=True)
        return r.returncode, r.stdout


def main():
    sound = {
        "include/cia402/drive.hpp": "#pragma once\n",
        "include/cia402/sim/plant.hpp": '#include "cia402/drive.hpp"\n',
        "src/sim/plant.cpp": '#include "cia402/sim/plant.hpp"\n',
    }
    checks = []
    code, out = run(sound)
    checks.append(("a sound tree passes", code == 0))
    upward = dict(sound)
    upward["src/core/drive.cpp"] = '#include "cia402/sim/plant.hpp"\n'
    code, out = run(upward)
    checks.append(("core including sim fails", code == 1 and "core may not include sim" in out))
    private = dict(sound)
    private["src/core/profiles/rows.hpp"] = "#pragma once\n"
    private["src/sim/scenario_file.cpp"] = '#include "profiles/rows.hpp"\n'
    code, out = run(private)
    checks.append(("a private header of another layer fails", code == 1 and "private" in out))
    code, out = run(private, "src/sim/scenario_file.cpp -> src/core/profiles/rows.hpp  # why\n")
    checks.append(("a listed breach passes", code == 0))
    code, out = run(sound, "src/sim/scenario_file.cpp -> src/core/profiles/rows.hpp  # why\n")
    checks.append(("a listed breach that is gone fails", code == 1 and "remove it" in out))
    failed = [name for name, ok in checks if not ok]
    for name, ok in checks:
        print(("ok   " if ok else "FAIL ") + name)
    print(f"{len(checks) - len(failed)} passed, {len(failed)} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
