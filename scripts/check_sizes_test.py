#!/usr/bin/env python3
"""The size check fails on a file over 600 lines, on a function over 150 lines (not on a namespace or
a class that long), in C++, JavaScript and Python alike, and on a stale exception, and passes a listed breach and a tree that keeps the
rules."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_test_support import report, run_check  # noqa: E402


def run(files, exceptions=""):
    return run_check("check_sizes.py", "size_exceptions.txt", files, exceptions)


def function(name, body_lines):
    return f"int {name}(int a) {{\n" + "  a += 1;  // '{{' in a comment\n" * (body_lines - 2) + "}\n"


def main():
    long_namespace = "namespace x {\nstruct big {\n" + function("inside", 150) + "};\n" + function("free", 150) * 2 + "}\n"
    sound = {"src/core/a.cpp": long_namespace, "include/cia402/a.hpp": "#pragma once\n" * 600}
    checks = []
    code, out = run(sound)
    checks.append(("functions of 150 lines in a namespace and a class pass", code == 0))
    big_file = dict(sound)
    big_file["tools/cli/b.cpp"] = "\n" * 601
    code, out = run(big_file)
    checks.append(("a file of 601 lines fails", code == 1 and "tools/cli/b.cpp: 601 lines" in out))
    big_function = dict(sound)
    big_function["src/sim/c.cpp"] = "namespace y {\n" + function("cut_me", 151) + "}\n"
    code, out = run(big_function)
    checks.append(("a function of 151 lines fails, named", code == 1 and "src/sim/c.cpp:cut_me: 151 lines" in out))
    method = dict(sound)
    method["src/sim/d.cpp"] = "int thing::method(int a) const {\n" + "  a += 1;\n" * 150 + "}\n"
    code, out = run(method)
    checks.append(("a member function is named with its class", code == 1 and "src/sim/d.cpp:thing::method" in out))
    scripts = dict(sound)
    scripts["src/page/web/ok.js"] = ("export function draw(a) {\n" + "  a += '{';  // a brace in a string\n" * 148
                                     + "}\nconst f = (b) => {\n  return `${b} }`;\n};\n")
    scripts["scripts/ok.py"] = "def fine(a):\n" + "    a += 1  # '{'\n" * 149 + "\n\ndef other():\n    pass\n"
    code, out = run(scripts)
    checks.append(("a JavaScript and a Python function of 150 lines pass", code == 0))
    long_js = dict(sound)
    long_js["src/page/web/long.js"] = "export function drawAll(a) {\n" + "  a += 1;\n" * 149 + "}\n"
    code, out = run(long_js)
    checks.append(("a JavaScript function of 151 lines fails, named",
                   code == 1 and "src/page/web/long.js:drawAll: 151 lines" in out))
    long_py = dict(sound)
    long_py["src/python/cia402/long.py"] = "class A:\n    def method(self):\n" + "        self.x = 1\n" * 150 + "x = 1\n"
    code, out = run(long_py)
    checks.append(("a Python function of 151 lines fails, named",
                   code == 1 and "src/python/cia402/long.py:method: 151 lines" in out))
    big_script = dict(sound)
    big_script["scripts/big.py"] = "x = 1\n" * 601
    big_script["src/page/web/big.js"] = "let x = 1;\n" * 601
    code, out = run(big_script)
    checks.append(("a .py or .js file of 601 lines fails",
                   code == 1 and "scripts/big.py: 601 lines" in out and "src/page/web/big.js: 601 lines" in out))
    code, out = run(big_function, "src/sim/c.cpp:cut_me  # why\n")
    checks.append(("a listed breach passes", code == 0))
    code, out = run(sound, "src/sim/c.cpp:cut_me  # why\n")
    checks.append(("a listed breach that is gone fails", code == 1 and "remove it" in out))
    return report(checks)


if __name__ == "__main__":
    sys.exit(main())
