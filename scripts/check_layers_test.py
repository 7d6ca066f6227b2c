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
    steering = dict(sound)
    steering["src/axis/session.cpp"] = "cia402::master m; master_policy p;\n"
    steering["src/ethercat/master/ecat_master.cpp"] = "// frames, not cia402::master steering\n"
    code, out = run(steering)
    checks.append(("the axis session may steer, a comment naming the master step is no steering", code == 0))
    steering["src/canopen/master/drive_master.cpp"] = "  s.policy = master_policy::make(p, a, t);\n"
    code, out = run(steering)
    checks.append(("a bus master that steers fails", code == 1 and "canopen/master steers a drive" in out))
    code, out = run(steering, "src/canopen/master/drive_master.cpp -> steering  # why\n")
    checks.append(("a listed steering breach passes", code == 0))
    fieldbus = dict(sound)
    fieldbus["include/cia402/sim/virtual_drive.hpp"] = "#pragma once\n"
    fieldbus["src/canopen/master/drive_master.cpp"] = '#include "cia402/sim/virtual_drive.hpp"\n'
    fieldbus["src/ethercat/slave/coe_slave.cpp"] = '#include "cia402/sim/virtual_drive.hpp"\n'
    code, out = run(fieldbus)
    checks.append(("canopen or ethercat including sim fails",
                   code == 1 and "canopen/master may not include sim" in out and "ethercat/slave may not include sim" in out))
    codec = dict(sound)
    codec["include/cia402/canopen/301/slave.hpp"] = "#pragma once\n"
    codec["src/ethercat/coe/sdo.cpp"] = '#include "cia402/canopen/301/slave.hpp"\n'
    code, out = run(codec)
    checks.append(("the CoE codec including canopen/301 fails", code == 1 and "ethercat/coe may not include canopen/301" in out))
    neutral = dict(sound)
    neutral["include/cia402/dictionary/device.hpp"] = "#pragma once\n"
    neutral["src/drive402/drive_objects.cpp"] = '#include "cia402/dictionary/device.hpp"\n'
    neutral["src/ethercat/slave/coe_slave.cpp"] = '#include "cia402/dictionary/device.hpp"\n'
    code, out = run(neutral)
    checks.append(("the drive device and the CoE slave on the neutral dictionary pass", code == 0))
    neutral["include/cia402/canopen/301/slave.hpp"] = "#pragma once\n"
    neutral["src/drive402/drive_objects.cpp"] = '#include "cia402/canopen/301/slave.hpp"\n'
    neutral["src/ethercat/slave/coe_slave.cpp"] = '#include "cia402/canopen/301/slave.hpp"\n'
    neutral["src/dictionary/object_dictionary.cpp"] = '#include "cia402/canopen/301/slave.hpp"\n'
    code, out = run(neutral)
    checks.append(("the drive device, the CoE slave or the dictionary including CANopen fails",
                   code == 1 and "drive402 may not include canopen/301" in out and
                   "ethercat/slave may not include canopen/301" in out and
                   "dictionary may not include canopen/301" in out))
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
