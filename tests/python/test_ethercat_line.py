"""cia402.ethercat.VirtualLine: virtual EtherCAT drives chained in this process and the project's
master over them, on virtual time: the bring-up to OP, the master's Axis over process data and CoE
SDO, and the line leaving OP when the master lets go; the same over a veth pair (as root). AL states
are ETG.1000.6's; objects CiA 402-2's."""
import os
import shutil
import subprocess
import sys

import pytest

import cia402
from cia402.ethercat import Axis, VirtualLine


def test_the_master_brings_a_line_of_drives_to_op_and_names_each():
    line = VirtualLine(drives=3)
    assert [s["position"] for s in line.slaves] == [0, 1, 2]
    assert [s["serial"] for s in line.slaves] == [1, 2, 3]
    assert all(s["name"] == "cia402 virtual drive" for s in line.slaves)
    assert all(line.al_state(p) == "OP" for p in range(3))
    cycles, time_ms = line.cycles, line.time_ms
    line.advance(50)
    assert line.time_ms == pytest.approx(time_ms + 50)
    assert line.cycles >= cycles + 49, "the process data keeps flowing without an axis"
    assert all(line.al_state(p) == "OP" for p in range(3))


def test_the_masters_axis_enables_moves_homes_and_turns_a_drive_over_the_process_data():
    line = VirtualLine(drives=2)
    axis = line.axis(1)
    assert isinstance(axis, Axis) and axis is not None
    assert axis.enable()["state"] == "OPERATION_ENABLED"
    assert axis.move(5000, velocity=1000)["position"] == 5000
    homed = axis.home(37)
    assert homed["mode"] == 6 and homed["position"] == 0
    assert abs(axis.velocity(300)["velocity"] - 300) <= 10
    assert axis.sdo_read(0x1008) == "cia402 virtual drive"
    assert axis.sdo_read(0x1018, 4) == 2  # the second drive's serial number
    with pytest.raises(cia402.SdoError) as e:
        axis.sdo_read(0x2005)
    assert e.value.code == 0x06020000
    axis.close()


def test_a_fault_over_coe_raises_axiserror_and_a_reset_recovers():
    axis = VirtualLine().axis(0)
    axis.enable()
    axis.sdo_write(0x2001, 0x2310, type="unsigned16")
    with pytest.raises(cia402.AxisError) as e:
        axis.move(100)
    assert e.value.error_code == 0x2310
    axis.sdo_write(0x2001, 0, type="unsigned16")
    assert axis.reset()["state"] == "SWITCH_ON_DISABLED"
    assert axis.enable()["state"] == "OPERATION_ENABLED"


def test_the_line_leaves_op_once_the_master_closes_its_last_axis():
    line = VirtualLine(drives=2)
    a, b = line.axis(0), line.axis(1)
    a.enable()
    a.close()
    line.advance(20)
    assert line.al_state(0) == "OP", "one axis is still open"
    b.close()
    line.advance(20)
    assert line.al_state(0) == "PRE-OP" and line.al_state(1) == "PRE-OP"


def test_a_line_refuses_sizes_and_positions_it_does_not_have():
    for bad in (0, 65):
        with pytest.raises(cia402.ArgumentError):
            VirtualLine(drives=bad)
    with pytest.raises(cia402.ArgumentError):
        VirtualLine(cycle_us=10)
    line = VirtualLine(drives=2)
    for bad in (-1, 2):
        with pytest.raises(cia402.ArgumentError):
            line.axis(bad)


VETH_BENCH = r"""
import subprocess, sys
from cia402.ethercat import VirtualLine
m, s = "c4m", "c4s"
subprocess.run(["ip", "link", "add", m, "type", "veth", "peer", "name", s], check=True)
for name in (m, s):
    subprocess.run(["ip", "link", "set", name, "up"], check=True)
line = VirtualLine(drives=2, interfaces=(m, s))
assert line.al_state(0) == "OP" and line.al_state(1) == "OP", [line.al_state(0), line.al_state(1)]
assert [d["serial"] for d in line.slaves] == [1, 2]
axis = line.axis(1)
assert axis.enable()["state"] == "OPERATION_ENABLED"
assert axis.move(4000, velocity=1000)["position"] == 4000
assert axis.sdo_read(0x1018, 4) == 2
try:
    line.advance(1)
    raise SystemExit("advance on wall time was not refused")
except ValueError:
    pass
axis.close()
cycles = line.cycles
print("over the veth pair: %d cycles" % cycles)
assert cycles > 100
"""


def test_a_line_over_a_veth_pair_in_a_network_namespace_runs_the_master_through_the_kernel():
    """The drives on one end of a veth pair, the master's raw socket on the other: the same axis
    requests as in process, on wall time. Made in a network namespace of its own (gone with it)."""
    if os.geteuid() != 0:
        pytest.skip("a network namespace, a veth pair and raw sockets need root (CAP_NET_ADMIN, CAP_NET_RAW)")
    if shutil.which("ip") is None:
        pytest.skip("iproute2 (ip) is not installed")
    namespace = "cia402py%d" % os.getpid()
    made = subprocess.run(["ip", "netns", "add", namespace], capture_output=True, text=True)
    if made.returncode != 0:
        pytest.skip("cannot make a network namespace here: " + made.stderr.strip())
    try:
        ran = subprocess.run(["ip", "netns", "exec", namespace, sys.executable, "-c", VETH_BENCH],
                             capture_output=True, text=True, timeout=120)
        assert ran.returncode == 0, ran.stdout + ran.stderr
        assert "over the veth pair" in ran.stdout
    finally:
        subprocess.run(["ip", "netns", "del", namespace], capture_output=True)


def test_a_line_over_interfaces_that_are_not_there_says_which():
    with pytest.raises(cia402.ArgumentError):
        VirtualLine(interfaces=("same", "same"))
    with pytest.raises(cia402.Error, match="interface"):
        VirtualLine(interfaces=("cia402-no-such-if0", "cia402-no-such-if1"))


def test_a_csv_stream_over_the_process_data_is_followed_and_a_jog_lapses_on_the_lines_time():
    line = VirtualLine()
    axis = line.axis(0)
    axis.enable()
    speeds = [min(10 * k, 600) for k in range(1, 201)]  # up to 600 rpm in 60 cycles, then held
    done = axis.stream(speeds, mode="csv")
    assert done["mode"] == 9 and abs(done["velocity"] - 600) <= 6 and done["set_points"] == 200
    assert done["trace"]["set_point"][:200] == speeds
    axis.jog(200, hold=0.05)
    line.advance(40)
    assert axis.busy
    assert abs(axis.wait()["velocity"]) <= 1 and not axis.busy
    axis.close()
