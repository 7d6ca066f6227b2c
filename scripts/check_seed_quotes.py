#!/usr/bin/env python3
"""Checks that the docs quote the seed lines they cite, so a clone can check every choice on its own.

The seeds are the vendors' manuals the profiles come from. They are not in the repository, so a doc
that cites a seed line (`002_522d2c0bb8f5a5f8.txt:81-83`, or `:81-83` for the seed last named on the
page) writes the words it rests on right after the citation, in quotation marks:

    `002_522d2c0bb8f5a5f8.txt:81-83` "Fault signal"
    `:119`, `:139` "Output stage is switched off (disabled) - motor loses torque"
    `:67-80` "Automatic transition when the quick", "stop option code 1, 2, 3 or 4"

Citations joined by commas or "and" share the quotes that follow; several quotes after one group
must each appear at each citation. A quote that itself holds a straight quotation mark is written
in curly ones (“ ”). Line breaks and runs of spaces count as one space.

Always checked, in README.md and docs/**/*.md: every citation is followed by a quote, and no doc
sends the reader to ../shared. Checked when the seed files are present (SEEDS, by default
ROOT/../shared/seeds, as the project keeps them beside its clone): every quote is in the seed at
the cited lines (line numbers as `cat -n` prints them). Exit 0 when all holds.

    python3 scripts/check_seed_quotes.py [ROOT [SEEDS]]
"""
import os
import re
import sys

SEED_NAME = r"\d{3}_[0-9a-f]{16}\.txt"
CITATION = re.compile(r"`(" + SEED_NAME + r")?:(\d+)(?:-(\d+))?`")
NAMED_SEED = re.compile(SEED_NAME)
JOINER = re.compile(r"(?:,\s*|\s+and\s+)(?=" + CITATION.pattern + ")")
QUOTE = re.compile(r'\s*:?\s*(?:"([^"]+)"|“([^”]+)”)')
QUOTE_SEPARATOR = re.compile(r",(?=\s*[\"“])")
OUTSIDE = re.compile(r"\.\./shared|/work/shared")


def spaced(text):
    return " ".join(text.split())


def doc_files(root):
    yield os.path.join(root, "README.md")
    for folder, _, names in os.walk(os.path.join(root, "docs")):
        for name in sorted(names):
            if name.endswith(".md"):
                yield os.path.join(folder, name)


def citation_groups(text):
    """(line, [(seed, first, last)], [quote]) per group of citations in a doc, in order.
    A citation without a seed name takes the last seed named before it."""
    groups, group, last_seed, pos = [], [], None, 0
    for m in CITATION.finditer(text):
        for named in NAMED_SEED.finditer(text, pos, m.start()):
            last_seed = named.group(0)
        last_seed = m.group(1) or last_seed
        pos = m.end()
        first = int(m.group(2))
        group.append((last_seed, first, int(m.group(3) or first)))
        if JOINER.match(text, m.end()):
            continue
        quotes, at = [], m.end()
        while True:
            q = QUOTE.match(text, at)
            if not q:
                break
            quotes.append(q.group(1) or q.group(2))
            at = q.end()
            sep = QUOTE_SEPARATOR.match(text, at)
            if not sep:
                break
            at = sep.end()
        groups.append((text.count("\n", 0, m.start()) + 1, group, quotes))
        group = []
    return groups


def check(root, seeds):
    problems, quotes_checked = [], 0
    seed_lines = {}
    for path in doc_files(root):
        if not os.path.exists(path):
            continue
        with open(path, encoding="utf-8") as f:
            text = f.read()
        where = os.path.relpath(path, root)
        for m in OUTSIDE.finditer(text):
            problems.append(f"{where}:{text.count(chr(10), 0, m.start()) + 1}: sends the reader to "
                            f"{m.group(0)}, outside the repository")
        for line, group, quotes in citation_groups(text):
            cited = ", ".join(f"{s}:{a}-{b}" for s, a, b in group)
            if not quotes:
                problems.append(f"{where}:{line}: {cited} is cited without the words it rests on")
                continue
            if seeds is None:
                continue
            for seed, first, last in group:
                if seed is None:
                    problems.append(f"{where}:{line}: a citation before any seed is named")
                    continue
                if seed not in seed_lines:
                    with open(os.path.join(seeds, seed), encoding="utf-8") as f:
                        seed_lines[seed] = f.read().split("\n")
                lines = seed_lines[seed]
                if not 1 <= first <= last <= len(lines):
                    problems.append(f"{where}:{line}: {seed}:{first}-{last} is not a line range "
                                    f"of the seed ({len(lines)} lines)")
                    continue
                at_lines = spaced("\n".join(lines[first - 1:last]))
                for quote in quotes:
                    quotes_checked += 1
                    if spaced(quote) not in at_lines:
                        problems.append(f'{where}:{line}: "{quote}" is not in {seed}:{first}-{last}')
    return problems, quotes_checked


def main(argv):
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    seeds = argv[2] if len(argv) > 2 else os.path.join(root, "..", "shared", "seeds")
    if not os.path.isdir(seeds):
        print(f"seed quotes: no seeds at {seeds}; checking only that each citation has its quote")
        seeds = None
    problems, quotes_checked = check(root, seeds)
    for p in problems:
        print(p)
    if problems:
        return 1
    print(f"seed quotes: every citation quotes its seed ({quotes_checked} quotes found at their lines)"
          if seeds else "seed quotes: every citation quotes its seed (seeds absent, quotes not looked up)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
