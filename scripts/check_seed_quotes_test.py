#!/usr/bin/env python3
"""The seed-quote check fails on a citation without its quote, on a quote that is not at its lines,
on a line range past the seed's end and on a doc that sends the reader to ../shared; it passes
quotes that are at their lines (across a line break, after a short `:N` citation, shared by joined
citations), and without the seeds it checks only that each citation has its quote."""
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SEED = "000_0123456789abcdef.txt"
SEED_TEXT = "T 1\n'Shutdown' command received\nThe motor is decelerated\nto standstill.\nnone\n'Shutdown' command received"


def run(doc, with_seeds=True):
    with tempfile.TemporaryDirectory() as top:
        root = os.path.join(top, "repo")
        os.makedirs(os.path.join(root, "docs", "profiles"))
        with open(os.path.join(root, "docs", "profiles", "p.md"), "w", encoding="utf-8") as f:
            f.write(doc)
        seeds = os.path.join(top, "shared", "seeds")
        if with_seeds:
            os.makedirs(seeds)
            with open(os.path.join(seeds, SEED), "w", encoding="utf-8") as f:
                f.write(SEED_TEXT)
        r = subprocess.run([sys.executable, os.path.join(HERE, "check_seed_quotes.py"), root],
                           capture_output=True, text=True)
        return r.returncode, r.stdout


def main():
    passes, fails = 0, 1
    cases = [
        ("quote at its lines", f'`{SEED}:2` "\'Shutdown\' command received"\n', True, passes,
         "1 quotes found"),
        ("quote across a line break", f'`{SEED}:3-4` "decelerated to standstill."\n', True, passes,
         "1 quotes found"),
        ("several quotes, short citations, joined citations",
         f'Seed `{SEED}` (`:2-3` "command received", "The motor", and `:2` and `:6` "command received")\n',
         True, passes, "4 quotes found"),
        ("curly quotes around a quote", f'`{SEED}:2` “\'Shutdown\'”\n', True, passes, "1 quotes found"),
        ("citation without its quote", f"`{SEED}:2` says Shutdown\n", True, fails, "without the words"),
        ("citation without its quote, no seeds", f"`{SEED}:2` says Shutdown\n", False, fails,
         "without the words"),
        ("quote not at the cited lines", f'`{SEED}:3` "\'Shutdown\' command received"\n', True, fails,
         "is not in"),
        ("a joined citation whose lines lack the shared quote", f'`{SEED}:2` and `:3` "command"\n', True,
         fails, f'"command" is not in {SEED}:3-3'),
        ("the second of two quotes is wrong", f'`{SEED}:2` "Shutdown", "Switch on"\n', True, fails,
         '"Switch on" is not in'),
        ("line range past the seed's end", f'`{SEED}:5-9` "none"\n', True, fails, "is not a line range"),
        ("a doc sending the reader to ../shared", "The seeds are in ../shared/seeds.\n", False, fails,
         "outside the repository"),
        ("wrong quote, no seeds: not looked up", f'`{SEED}:3` "Switch on"\n', False, passes,
         "quotes not looked up"),
    ]
    failed = 0
    for name, doc, with_seeds, expected, says in cases:
        code, out = run(doc, with_seeds)
        if code != expected or says not in out:
            print(f"FAIL {name}: exit {code}, expected {expected} and output with {says!r}\n{out}")
            failed += 1
    print(f"{len(cases) - failed} of {len(cases)} cases as expected")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
