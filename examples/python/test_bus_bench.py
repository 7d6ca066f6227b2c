"""A hardware-less bench over a fieldbus: the project's master (`Axis`) drives a virtual drive over
CANopen (`cia402.canopen.VirtualBus`: SDO, PDOs, SYNC every 10 ms) and over EtherCAT
(`cia402.ethercat.VirtualLine`: process data every 1 ms, CoE SDO). Every test runs on both buses,
on virtual time: a request steps the bus itself until it ends, so a loaded CI host fails nothing.

    PYTHONPATH=build/release/python python3 -m pytest examples/python/test_bus_bench.py

Each test is a bench procedure: enable, a profile position move, homing, a fault and its reset, a
jog that stops by itself when its time to live lapses, and a csp stream checked against what the
drive did each cycle (and, on CANopen, against the frames on the bus).
"""
import struct

import pytest

import cia402
from cia402.canopen import VirtualBus
from cia402.ethercat import VirtualLine

NODE = 1
FAULT_INJECTION = 0x2001  # the virtual drive's own object: an error code raised as a fault
OVER_CURRENT = 0x2310     # CiA 301 error code: continuous over-current


def open_bench(kind, csp=False):
    """(the bus or line, the master's axis for its drive); time moves only when asked to. On
    CANopen `csp` maps PDO 3 (0x6040 + 0x607A out, 0x6041 + 0x6064 in, on SYNC) for a csp stream."""
    if kind == "canopen":
        bus = VirtualBus(nodes=[NODE], virtual_time=True)
        return bus, bus.axis(NODE, cycle_ms=10, map_position=csp)
    line = VirtualLine(drives=1, cycle_us=1000)  # the line maps 0x607A, 0x60FF, 0x6071 already
    return line, line.axis(0)


@pytest.fixture(params=["canopen", "ethercat"])
def bench(request):
    bus, axis = open_bench(request.param)
    yield bus, axis
    axis.close()
    if isinstance(bus, VirtualBus):
        bus.close()


def test_enable_walks_to_operation_enabled(bench):
    _, axis = bench
    done = axis.enable()
    assert done["state"] == "OPERATION_ENABLED" and axis.state == "OPERATION_ENABLED"
    assert done["status_word"] & 0x6F == 0x27  # CiA 402 Table 30: operation enabled


def test_a_profile_position_move_ends_at_the_target(bench):
    _, axis = bench
    axis.enable()
    assert axis.move(50_000, velocity=1000)["position"] == 50_000
    back = axis.move(-20_000, relative=True)
    assert back["position"] == 30_000 and back["mode"] == 1  # pp
    assert back["status_word"] & 0x0400  # target reached


def test_homing_method_37_makes_where_the_drive_stands_its_home(bench):
    _, axis = bench
    axis.enable()
    axis.move(12_345, velocity=1000)
    homed = axis.home(37, offset=500)
    assert homed["mode"] == 6 and homed["position"] == 500
    attained = (1 << 12) | (1 << 10)  # homing attained, target reached
    assert homed["status_word"] & attained == attained


def test_a_fault_is_reported_with_its_code_and_a_reset_brings_the_drive_back(bench):
    _, axis = bench
    axis.enable()
    axis.sdo_write(FAULT_INJECTION, OVER_CURRENT, type="unsigned16")
    with pytest.raises(cia402.AxisError) as fault:
        axis.move(1000)
    assert fault.value.error_code == OVER_CURRENT
    assert fault.value.state in ("FAULT", "FAULT_REACTION_ACTIVE")
    axis.sdo_write(FAULT_INJECTION, 0, type="unsigned16")  # the cause gone; the fault stays until reset
    assert axis.state_of()["state"] == "FAULT"
    assert axis.reset()["state"] == "SWITCH_ON_DISABLED"
    assert axis.enable()["state"] == "OPERATION_ENABLED"


def test_a_jog_runs_while_renewed_and_stops_by_itself_when_its_time_to_live_lapses(bench):
    bus, axis = bench
    axis.enable()
    started = axis.jog(300, hold=0.2)
    assert started["velocity"] == 300 and axis.busy
    for _ in range(5):              # a button held for 0.5 s: renewed every 0.1 s
        bus.advance(100)
        axis.renew_jog(0.2)
    assert axis.busy and abs(axis.sdo_read(0x606C) - 300) <= 3
    stopped = axis.wait(timeout=5)  # released: 0.2 s later the drive ramps to standstill
    assert abs(stopped["velocity"]) <= 1 and stopped["state"] == "OPERATION_ENABLED"
    assert not axis.busy


# Cycles from a set-point going out to the master seeing the drive stand at it, fixed by each bus's
# timing (measured with these drives): on CANopen RPDO3 is taken at the SYNC after it and TPDO3
# answers that SYNC; on EtherCAT the outputs of one frame are taken at the SYNC0 pulse after it, and
# the slave steps the drive before it fills the inputs, so the next frame brings the answer back.
REPORTED_AFTER = {"canopen": 2, "ethercat": 2}


@pytest.mark.parametrize("kind", ["canopen", "ethercat"])
def test_a_csp_stream_is_followed_cycle_by_cycle(kind):
    bus, axis = open_bench(kind, csp=True)
    axis.enable()
    ramp = [100 * k for k in range(1, 201)]  # 100 increments a cycle
    done = axis.stream(ramp, mode="csp")
    assert done["position"] == ramp[-1] and done["set_points"] == len(ramp)
    sent, actual = done["trace"]["set_point"], done["trace"]["actual"]
    assert sent[:len(ramp)] == ramp
    # Each set-point reached exactly, in the same number of cycles for every one.
    lag = REPORTED_AFTER[kind]
    # the last one reached is done["position"], in the cycle that ends the stream
    assert actual[lag:] == ramp[:-1]
    axis.close()
    if isinstance(bus, VirtualBus):
        bus.close()


def test_the_csp_set_points_are_on_the_bus_as_rpdo3_frames():
    """On CANopen, the set-points the stream sent are the frames a bus monitor sees: RPDO3
    (0x400 + node) carrying the control word and 0x607A (the mapping the master set up)."""
    bus, axis = open_bench("canopen", csp=True)
    with bus:
        monitor = bus.attach()  # a listener on the bus, as candump would be
        axis.enable()
        ramp = [-50 * k for k in range(1, 101)]
        axis.stream(ramp)
        rpdo3 = []
        while (frame := monitor.recv(timeout=0)) is not None:
            can_id, data = frame[0], frame[1]
            if can_id == 0x400 + NODE:
                rpdo3.append(struct.unpack_from("<i", data, 2)[0])
        first = rpdo3.index(ramp[0])
        assert rpdo3[first:first + len(ramp)] == ramp
        axis.close()
