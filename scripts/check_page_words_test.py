#!/usr/bin/env python3
"""check_page_words.py fails on each kind of raw control-word bit literal and passes the page's idioms."""
import pathlib
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
BAD = ["constexpr std::uint16_t bit4 = 1u << 4;", "if ((sw & (1u << 12)) != 0) {}",
       "w = word | 0x0010;", "w = word & ~0x80;", "if (0x0080 & word) {}", "w ^= 16;"]
GOOD = ["w = word | control_bit::new_set_point;", "const auto code = e & 0xFFFFu;",
        "if (((known >> k) & 1u) != 0) {}", "std::size_t max = 1 << 20;", 'text = "bit 4 | 0x10";',
        "// word & 0x0010 in a comment", "out += char(0x80 | c);  // not a control word",
        "if (a && 0x10 > b || c) {}"]


def run(line: str) -> int:
    with tempfile.NamedTemporaryFile("w", suffix=".cpp", delete=False) as f:
        f.write(line + "\n")
    return subprocess.run([sys.executable, str(HERE / "check_page_words.py"), ".", f.name],
                          capture_output=True).returncode


failed = [f"passed: {b}" for b in BAD if run(b) != 1] + [f"failed: {g}" for g in GOOD if run(g) != 0]
for f in failed:
    print(f)
sys.exit(1 if failed else 0)
