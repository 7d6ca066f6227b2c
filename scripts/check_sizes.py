#!/usr/bin/env python3
"""Checks the size rules of the project on its product code (src/, include/, tools/ and scripts/): no
source file over 600 lines, no function over 150 lines, in C++, JavaScript (the page's scripts) and
Python alike. In C++ and JavaScript a function is a brace-delimited body whose opening statement has
a parameter list, at namespace, class or module scope (a JavaScript arrow function's body too); its
lines run from the line of its opening brace to the line of its closing one. In Python a function
runs from its `def` to its body's last line. Comments and string literals are left out of the
reading, not of the count.

Known breaches, each with its reason, are listed in scripts/size_exceptions.txt as FILE (a file over
600 lines) or FILE:FUNCTION (a function over 150, named as it is defined, e.g. drive::step): a new
breach fails, and so does a listed one that is gone (the list must stay true). Exit 0 when every
file and function keeps the rules.

    python3 scripts/check_sizes.py [ROOT]
"""
import os
import re
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 150
TOPS = ("src", "include", "tools", "scripts")
SUFFIXES = (".cpp", ".hpp", ".h", ".js", ".mjs", ".py")


def blanked(text):
    """The text with comments and string and character literals blanked, newlines kept."""
    def keep_lines(m):
        return re.sub(r"[^\n]", " ", m.group(0))
    text = re.sub(r'R"([^(\s]*)\(.*?\)\1"', keep_lines, text, flags=re.S)
    text = re.sub(r"`(\\.|[^`\\])*`", keep_lines, text, flags=re.S)  # JavaScript template literals
    text = re.sub(r"/\*.*?\*/", keep_lines, text, flags=re.S)
    text = re.sub(r"//[^\n]*", keep_lines, text)
    text = re.sub(r'"(\\.|[^"\\\n])*"', keep_lines, text)
    return re.sub(r"'(\\.|[^'\\\n])+'", keep_lines, text)


def function_name(statement):
    """The name before the parameter list: `void drive_master::build_script()` -> drive_master::build_script."""
    head = statement.split("(", 1)[0].strip()
    words = re.findall(r"[~\w:]+", head)
    return words[-1] if words else head


def functions(text):
    """(name, first line, last line) of every function body."""
    stack = []  # ("namespace" | "class" | "block") or ("function", name, line)
    statement = ""
    line = 1
    found = []
    for ch in blanked(text):
        if ch == "\n":
            line += 1
        if ch == "{":
            s = " ".join(statement.split())
            if any(kind[0] == "function" for kind in stack):
                kind = ("block",)
            elif re.match(r"^(inline\s+)?namespace\b|^extern\s", s):
                kind = ("namespace",)
            elif re.match(r"^(template\s*<.*>\s*)?(class|struct|union|enum)\b", s) and "(" not in s:
                kind = ("class",)
            elif "(" in s and not s.endswith("=") and not re.match(r"^(template\s*<.*>\s*)?(class|struct|union|enum)\b", s):
                kind = ("function", function_name(s), line)
            else:
                kind = ("block",)
            stack.append(kind)
            statement = ""
        elif ch == "}":
            if stack:
                kind = stack.pop()
                if kind[0] == "function":
                    found.append((kind[1], kind[2], line))
            statement = ""
        elif ch == ";":
            statement = ""
        else:
            statement += ch
    return found


def python_functions(text):
    """(name, first line, last line) of every Python function: its `def` line to the last line
    indented deeper than the `def` (a nested function is counted in its own right too)."""
    lines = text.split("\n")
    found = []
    for i, line in enumerate(lines):
        m = re.match(r"^(\s*)(async\s+)?def\s+(\w+)", line)
        if not m:
            continue
        indent = len(m.group(1))
        last = i
        for j in range(i + 1, len(lines)):
            body = lines[j]
            if not body.strip():
                continue
            if len(body) - len(body.lstrip()) <= indent:
                break
            last = j
        found.append((m.group(3), i + 1, last + 1))
    return found


def breaches(root):
    found = []  # (key, why)
    for top in TOPS:
        for folder, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if not f.endswith(SUFFIXES):
                    continue
                path = os.path.relpath(os.path.join(folder, f), root)
                with open(os.path.join(root, path), encoding="utf-8") as text_file:
                    text = text_file.read()
                lines = text.count("\n")
                if lines > MAX_FILE_LINES:
                    found.append((path, f"{lines} lines, more than {MAX_FILE_LINES}"))
                reader = python_functions if f.endswith(".py") else functions
                for name, first, last in reader(text):
                    length = last - first + 1
                    if length > MAX_FUNCTION_LINES:
                        found.append((f"{path}:{name}", f"{length} lines from line {first}, more than {MAX_FUNCTION_LINES}"))
    return found


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    listed = set()
    exceptions = os.path.join(root, "scripts", "size_exceptions.txt")
    if os.path.exists(exceptions):
        with open(exceptions, encoding="utf-8") as f:
            for entry in f:
                entry = entry.split("#", 1)[0].strip()
                if entry:
                    listed.add(entry)
    failed = False
    seen = set()
    for key, why in breaches(root):
        seen.add(key)
        if key not in listed:
            print(f"{key}: {why}")
            failed = True
    for key in sorted(listed - seen):
        print(f"{key} is listed in size_exceptions.txt but keeps the rules now: remove it from the list")
        failed = True
    print(f"files over {MAX_FILE_LINES} lines or functions over {MAX_FUNCTION_LINES} still listed: {len(listed)}; "
          + ("FAILED" if failed else "every other file and function keeps the rules"))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
