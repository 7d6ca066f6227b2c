#!/usr/bin/env python3
"""The page steers no control word itself: no raw control-word bit literals in src/page.

The axis session (src/axis) is the one master; the page asks it for every handshake and names the
bits it only displays by the core's words (include/cia402/words.hpp: control_bit::, status_bit::).
Fails (exit 1), naming file and line, on a shift of 1 by a literal (`1u << 4`) or a hex or decimal
literal in a bit operation (`word & 0x0010`, `0x80 | w`, `~0x10`), outside strings and comments;
not on an all-ones mask (`& 0xFFFF`), `& 1u` after a shift, or a line that says "not a control word".

Usage: check_page_words.py <project root> [files...]  (files: check these instead of src/page)
"""
import pathlib
import re
import sys

SHIFT = re.compile(r"\b1[uU]?\s*<<\s*(\d+)")
LITERAL = r"(0[xX][0-9a-fA-F]+|\d+)[uU]?\b"
BIT_OP = [re.compile(r"[&|^~]=?\s*\(?\s*" + LITERAL), re.compile(r"\b" + LITERAL + r"\s*[&|^]")]
# A line that says so holds bits that are not the drive's words (UTF-8 bytes, a bit set's own).
NOT_A_WORD = "not a control word"


def word_literal(text: str) -> bool:
    """A literal that can be control-word bits: hex but an all-ones mask (0xFF, 0xFFFF), decimal > 1."""
    value = int(text, 0)
    if text.lower().startswith("0x"):
        return value != 0 and (value + 1) & value != 0
    return value > 1


def breach(code: str) -> bool:
    if any(int(m.group(1)) <= 15 for m in SHIFT.finditer(code)):
        return True
    return any(word_literal(m.group(1)) for r in BIT_OP for m in r.finditer(code))


def code_of(line: str) -> str:
    """The line without string and character literals and without a // comment."""
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])*'", "''", line)
    return line.split("//", 1)[0]


def breaches(path: pathlib.Path):
    in_block = False
    for number, raw in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        line = raw
        if in_block:
            if "*/" not in line:
                continue
            line = line.split("*/", 1)[1]
            in_block = False
        if "/*" in line:
            head, _, tail = line.partition("/*")
            in_block = "*/" not in tail
            line = head
        code = code_of(line)
        # `&&`/`||` are not bit operations: left out before the search.
        code = code.replace("&&", "  ").replace("||", "  ")
        if NOT_A_WORD not in raw and breach(code):
            yield number, raw.strip()


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    root = pathlib.Path(argv[1])
    files = [pathlib.Path(f) for f in argv[2:]] or sorted(
        p for p in (root / "src" / "page").rglob("*") if p.suffix in (".cpp", ".hpp", ".h"))
    found = 0
    for f in files:
        for number, text in breaches(f):
            print(f"{f}:{number}: raw control-word bit literal in the page: {text}")
            found += 1
    if found:
        print(f"{found} raw bit literal(s): use the session's calls or cia402/words.hpp's named bits")
        return 1
    print(f"check_page_words: {len(files)} files, no raw control-word bit literal")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
