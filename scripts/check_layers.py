#!/usr/bin/env python3
"""Checks the link rules between the project's layers by reading every #include line.

Each file of src/, include/ and tools/ belongs to one layer (LAYERS, by path). A layer may include
its own files and the public headers of the layers it is allowed to see (ALLOWED); never a layer
above it, and never another layer's private files (src/<layer>/...). docs/architecture.md draws the
same rules. Known breaches that the restructuring still has to remove are listed in
scripts/layer_exceptions.txt, each with its reason: a new breach fails, and so does a listed one
that is gone (the list must stay true). Exit 0 when every include keeps the rules.

    python3 scripts/check_layers.py [ROOT]
"""
import os
import re
import sys

# (layer, path prefix) in the order they are matched: the first prefix that fits wins.
LAYERS = [
    ("core", "include/cia402/detail/"),
    ("axis", "include/cia402/axis/"),
    ("axis", "src/axis/"),
    ("canopen/axis", "include/cia402/canopen/axis/"),
    ("canopen/axis", "src/canopen/axis/"),
    ("ethercat/axis", "include/cia402/ethercat/axis/"),
    ("ethercat/axis", "src/ethercat/axis/"),
    ("motion", "include/cia402/motion/"),
    ("motion", "src/motion/"),
    ("sim", "include/cia402/sim/"),
    ("sim", "src/sim/"),
    ("drive402", "include/cia402/drive402/"),
    ("drive402", "src/drive402/"),
    ("canopen/master", "include/cia402/canopen/master/"),
    ("canopen/master", "src/canopen/master/"),
    ("canopen/306", "include/cia402/canopen/306/"),
    ("canopen/306", "src/canopen/306/"),
    ("canopen/can", "include/cia402/canopen/can/"),
    ("canopen/transport", "include/cia402/canopen/transport/"),
    ("canopen/transport", "src/canopen/transport/"),
    ("canopen/monitor", "include/cia402/canopen/monitor/"),
    ("canopen/monitor", "src/canopen/monitor/"),
    ("dictionary", "include/cia402/dictionary/"),
    ("dictionary", "src/dictionary/"),
    ("canopen/301", "include/cia402/canopen/301/"),
    ("canopen/301", "src/canopen/301/"),
    ("ethercat/esc", "include/cia402/ethercat/esc/"),
    ("ethercat/esc", "src/ethercat/esc/"),
    ("ethercat/sii", "include/cia402/ethercat/sii/"),
    ("ethercat/sii", "src/ethercat/sii/"),
    ("ethercat/coe", "include/cia402/ethercat/coe/"),
    ("ethercat/coe", "src/ethercat/coe/"),
    ("ethercat/slave", "include/cia402/ethercat/slave/"),
    ("ethercat/slave", "src/ethercat/slave/"),
    ("ethercat/master", "include/cia402/ethercat/master/"),
    ("ethercat/master", "src/ethercat/master/"),
    ("apps", "include/cia402/apps/"),
    ("apps", "src/apps/"),
    ("page", "src/page/"),
    ("python", "src/python/"),
    ("support", "src/support/"),
    ("profile_file", "include/cia402/profile_file.hpp"),
    ("profile_file", "src/profile_file/"),
    ("diagram", "include/cia402/diagram.hpp"),
    ("diagram", "src/diagram/"),
    ("replay", "include/cia402/replay.hpp"),
    ("replay", "src/replay/"),
    ("core", "include/cia402/"),
    ("core", "src/core/"),
    ("tools", "tools/"),
]

# What each layer may include besides itself. Dependencies point downward only.
ALLOWED = {
    "core": set(),
    "motion": set(),
    "support": set(),
    "profile_file": {"core", "support"},
    "diagram": {"core"},
    "replay": {"core", "support"},
    "sim": {"core", "profile_file", "motion", "support"},
    "dictionary": {"core"},
    "canopen/can": {"core"},
    "canopen/301": {"core", "dictionary", "canopen/can"},
    "canopen/306": {"core", "support", "dictionary", "canopen/can", "canopen/301"},
    "canopen/transport": {"core", "support", "canopen/can"},
    "canopen/monitor": {"core", "dictionary", "canopen/can", "canopen/301"},
    "canopen/master": {"core", "support", "canopen/can", "canopen/301", "canopen/306"},
    "drive402": {"core", "motion", "sim", "dictionary"},
    "ethercat/esc": set(),
    "ethercat/sii": {"support"},
    "ethercat/coe": {"core"},
    "ethercat/slave": {"core", "dictionary", "ethercat/esc", "ethercat/sii", "ethercat/coe"},
    "ethercat/master": {"core", "ethercat/esc", "ethercat/sii", "ethercat/coe"},
    # The axis session and its links: the session sees the core only; each link its own fieldbus.
    "axis": {"core"},
    "canopen/axis": {"core", "axis", "support", "dictionary", "canopen/can", "canopen/301", "canopen/306", "canopen/master"},
    "ethercat/axis": {"core", "axis", "ethercat/esc", "ethercat/sii", "ethercat/coe", "ethercat/master"},
    # The compositions: canopen/axis for the CiA 301 types' value formats the local link shares.
    "apps": {"axis", "dictionary", "canopen/axis", "ethercat/master", "ethercat/esc", "ethercat/sii", "ethercat/coe", "ethercat/slave", "drive402", "sim", "motion", "support",
             "core", "canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
             "canopen/monitor"},
    # The page is a client of the axis session; `cia402 serve` (tools) builds the link.
    "page": {"core", "motion", "support", "profile_file", "diagram", "sim", "axis"},
    # The Python binding: the core, profile files, the replay, the simulator, and the fieldbuses as
    # the apps layer composes them (the virtual CAN bus with its drives, the axis session).
    "python": {"core", "motion", "support", "profile_file", "replay", "sim", "apps", "drive402", "dictionary",
               "canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
               "canopen/monitor", "axis", "canopen/axis", "ethercat/esc", "ethercat/sii",
               "ethercat/coe", "ethercat/slave", "ethercat/master", "ethercat/axis"},
    "tools": {"core", "motion", "support", "profile_file", "diagram", "replay", "sim", "dictionary", "canopen/can",
              "canopen/301", "canopen/306", "canopen/transport", "canopen/master", "canopen/monitor",
              "drive402", "apps", "page", "axis", "canopen/axis", "ethercat/axis",
              "ethercat/esc", "ethercat/sii", "ethercat/coe", "ethercat/slave", "ethercat/master"},
}

# What a layer may never see, whatever ALLOWED says: the fieldbuses know no simulated drive (the
# drive402 device sits on the neutral object dictionary, the compositions that put it on a bus are the
# apps layer's), the CoE codec sees only the core so the master can use it, the master nothing of the
# slave side, the drive and the dictionary no fieldbus at all, and the page no fieldbus at all
# (a client of the axis session; `cia402 serve` builds the link). check_rules() holds ALLOWED to
# these before any file is read, so the table cannot be widened past them by accident.
NEVER = [
    ("canopen/", {"sim", "motion", "drive402", "apps", "page"}),
    ("ethercat/", {"sim", "motion", "drive402", "apps", "page"}),
    ("ethercat/coe", {"canopen/can", "canopen/301"}),
    ("ethercat/master", {"ethercat/slave"}),
    ("page", {"canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
              "canopen/monitor", "canopen/axis", "ethercat/esc", "ethercat/sii", "ethercat/coe",
              "ethercat/slave", "ethercat/master", "ethercat/axis", "apps", "drive402"}),
    ("drive402", {"canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
                  "canopen/monitor", "canopen/axis", "ethercat/esc", "ethercat/sii", "ethercat/coe",
                  "ethercat/slave", "ethercat/master", "ethercat/axis"}),
    # The object dictionary is fieldbus-neutral, and no EtherCAT layer sees CANopen: the CoE slave
    # mounts the same dictionary the CANopen node does.
    ("dictionary", {"canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
                    "canopen/monitor", "canopen/axis", "ethercat/esc", "ethercat/sii", "ethercat/coe",
                    "ethercat/slave", "ethercat/master", "ethercat/axis"}),
    ("ethercat/", {"canopen/can", "canopen/301", "canopen/306", "canopen/transport", "canopen/master",
                   "canopen/monitor", "canopen/axis"}),
]

# Where a quoted include is looked for, after the including file's own folder.
INCLUDE_ROOTS = ["include", "src/page/include", "src/support/include", "src/core", "tools"]

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')

# The session is the one master: only the core (which defines it) and the axis session may steer a
# drive with the core's master step, i.e. name `master_policy` or the class `cia402::master`. A bus
# master carries words. A breach is listed in layer_exceptions.txt as `FILE -> steering`.
STEERS = {"core", "axis"}
STEERING = re.compile(r"\bmaster_policy\b|\bcia402::master\b(?!_)")


def check_rules(allowed):
    """Each (layer, layer it may never see) that ALLOWED permits all the same."""
    conflicts = []
    for prefix, never in NEVER:
        for layer, seen in allowed.items():
            if layer.startswith(prefix):
                conflicts.extend((layer, other) for other in sorted(seen & never))
    return conflicts


def layer_of(path):
    for layer, prefix in LAYERS:
        if path.startswith(prefix):
            return layer
    return None


def public(path):
    """A header other layers may include: under include/ or a layer's own include/ folder."""
    return path.startswith("include/") or "/include/" in path


def resolve(root, including, name):
    candidates = [os.path.join(os.path.dirname(including), name)]
    candidates += [os.path.join(r, name) for r in INCLUDE_ROOTS]
    for c in candidates:
        full = os.path.normpath(os.path.join(root, c))
        if os.path.isfile(full):
            return os.path.relpath(full, root)
    return None


def breaches(root):
    found = []
    found_steering = set()
    for top in ("include", "src", "tools"):
        for folder, _, files in os.walk(os.path.join(root, top)):
            for f in sorted(files):
                if not f.endswith((".hpp", ".cpp", ".h")):
                    continue
                path = os.path.relpath(os.path.join(folder, f), root)
                mine = layer_of(path)
                if mine is None:
                    continue
                with open(os.path.join(root, path), encoding="utf-8") as text:
                    for line in text:
                        code = line.split("//", 1)[0]
                        if mine not in STEERS and STEERING.search(code) and (path, "steering") not in found_steering:
                            found_steering.add((path, "steering"))
                            found.append((path, "steering", f"{mine} steers a drive: only the axis session may"))
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = resolve(root, path, m.group(1))
                        theirs = layer_of(target) if target else None
                        if theirs is None or theirs == mine:
                            continue
                        if theirs not in ALLOWED[mine]:
                            found.append((path, target, f"{mine} may not include {theirs}"))
                        elif not public(target):
                            found.append((path, target, f"a private file of {theirs}"))
    return found


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    listed = {}
    with open(os.path.join(root, "scripts", "layer_exceptions.txt"), encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                source, _, target = line.partition(" -> ")
                listed[(source.strip(), target.strip())] = True
    failed = False
    for layer, other in check_rules(ALLOWED):
        print(f"the rules let {layer} include {other}, which it may never see (NEVER)")
        failed = True
    seen = set()
    for source, target, why in breaches(root):
        seen.add((source, target))
        if (source, target) not in listed:
            print(f"{source}: {why}" if target == "steering" else f"{source} includes {target}: {why}")
            failed = True
    for pair in listed:
        if pair not in seen:
            print(f"{pair[0]} -> {pair[1]} is listed in layer_exceptions.txt but keeps the rules now: "
                  "remove it from the list")
            failed = True
    layers = sorted(ALLOWED)
    print(f"layers: {len(layers)}; known breaches still listed: {len(listed)}; "
          + ("FAILED" if failed else "every other include keeps the rules"))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
