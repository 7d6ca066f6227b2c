#!/usr/bin/env python3
"""The layer check fails on an upward include, on a private include, on a fieldbus that includes the
simulator, on a CoE codec, a drive device, a CoE slave or the object dictionary that
includes canopen, on a rule table that would allow either, and on a stale
exception, and passes a tree that keeps the rules."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_test_support import report, run_check  # noqa: E402


def run(files, exceptions=""):
    return run_check("check_layers.py", "layer_exceptions.txt", files, exceptions)


# Each case is the sound tree with a few files added; the check must pass it, or fail it naming
# every breach it holds (one helper each, so a case says only its files and its expected words).
def passes(files, exceptions=""):
    code, _ = run(files, exceptions)
    return code == 0


def fails_saying(files, *messages, exceptions=""):
    code, out = run(files, exceptions)
    return code == 1 and all(m in out for m in messages)


HEADER = "#pragma once\n"


def including(header):
    return f'#include "{header}"\n'


def main():
    sound = {
        "include/cia402/drive.hpp": HEADER,
        "include/cia402/sim/plant.hpp": including("cia402/drive.hpp"),
        "src/sim/plant.cpp": including("cia402/sim/plant.hpp"),
    }
    checks = []
    checks.append(("a sound tree passes", passes(sound)))
    upward = {**sound, "src/core/drive.cpp": including("cia402/sim/plant.hpp")}
    checks.append(("core including sim fails", fails_saying(upward, "core may not include sim")))
    private = {**sound, "src/core/profiles/rows.hpp": HEADER,
               "src/sim/scenario_file.cpp": including("profiles/rows.hpp")}
    checks.append(("a private header of another layer fails", fails_saying(private, "private")))
    listed = "src/sim/scenario_file.cpp -> src/core/profiles/rows.hpp  # why\n"
    checks.append(("a listed breach passes", passes(private, listed)))
    checks.append(("a listed breach that is gone fails", fails_saying(sound, "remove it", exceptions=listed)))
    steering = {**sound, "src/axis/session.cpp": "cia402::master m; master_policy p;\n",
                "src/ethercat/master/ecat_master.cpp": "// frames, not cia402::master steering\n"}
    checks.append(("the axis session may steer, a comment naming the master step is no steering",
                   passes(steering)))
    steering["src/canopen/master/drive_master.cpp"] = "  s.policy = master_policy::make(p, a, t);\n"
    checks.append(("a bus master that steers fails", fails_saying(steering, "canopen/master steers a drive")))
    checks.append(("a listed steering breach passes",
                   passes(steering, "src/canopen/master/drive_master.cpp -> steering  # why\n")))
    fieldbus = {**sound, "include/cia402/sim/virtual_drive.hpp": HEADER,
                "src/canopen/master/drive_master.cpp": including("cia402/sim/virtual_drive.hpp"),
                "src/ethercat/slave/coe_slave.cpp": including("cia402/sim/virtual_drive.hpp")}
    checks.append(("canopen or ethercat including sim fails",
                   fails_saying(fieldbus, "canopen/master may not include sim", "ethercat/slave may not include sim")))
    codec = {**sound, "include/cia402/canopen/301/slave.hpp": HEADER,
             "src/ethercat/coe/sdo.cpp": including("cia402/canopen/301/slave.hpp")}
    checks.append(("the CoE codec including canopen/301 fails",
                   fails_saying(codec, "ethercat/coe may not include canopen/301")))
    neutral = {**sound, "include/cia402/dictionary/device.hpp": HEADER,
               "src/drive402/drive_objects.cpp": including("cia402/dictionary/device.hpp"),
               "src/ethercat/slave/coe_slave.cpp": including("cia402/dictionary/device.hpp")}
    checks.append(("the drive device and the CoE slave on the neutral dictionary pass", passes(neutral)))
    on_canopen = {**neutral, "include/cia402/canopen/301/slave.hpp": HEADER}
    for user in ("src/drive402/drive_objects.cpp", "src/ethercat/slave/coe_slave.cpp",
                 "src/dictionary/object_dictionary.cpp"):
        on_canopen[user] = including("cia402/canopen/301/slave.hpp")
    checks.append(("the drive device, the CoE slave or the dictionary including CANopen fails",
                   fails_saying(on_canopen, "drive402 may not include canopen/301",
                                "ethercat/slave may not include canopen/301", "dictionary may not include canopen/301")))
    import check_layers
    widened = {layer: set(seen) for layer, seen in check_layers.ALLOWED.items()}
    widened["canopen/master"].add("sim")
    widened["ethercat/master"].add("ethercat/slave")
    checks.append(("the rule table itself may not let a fieldbus see the simulator",
                   check_layers.check_rules(check_layers.ALLOWED) == [] and
                   ("canopen/master", "sim") in check_layers.check_rules(widened) and
                   ("ethercat/master", "ethercat/slave") in check_layers.check_rules(widened)))
    return report(checks)


if __name__ == "__main__":
    sys.exit(main())
