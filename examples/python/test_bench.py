"""A hardware-less test bench in pytest: one virtual drive on the simulator's plant, driven through
its objects as a master would over a fieldbus. Run it against a built package:

    PYTHONPATH=build/release/python python3 -m pytest examples/python

Each test is a bench procedure: enable, a profile position move, homing, a fault and its reset,
and a csp stream checked against the recorded trace.
"""
import pytest

import cia402
from cia402 import sim

SHUTDOWN, ENABLE_OPERATION, FAULT_RESET = 0x06, 0x0F, 0x80
NEW_SET_POINT = 0x10  # control word bit 4 in pp; "homing operation start" in hm
TARGET_REACHED, SET_POINT_ACK, HOMING_ATTAINED = 0x0400, 0x1000, 0x1000


def values(column):
    return column.tolist() if hasattr(column, "tolist") else list(column)


@pytest.fixture
def machine():
    """One axis on the default plant (1 ms cycle, brake, 10,000 increments a revolution), every
    cycle recorded."""
    return sim.Machine(axes=1, trace=[0])


def advance_until(machine, condition, limit_ms):
    """Steps 1 ms at a time until `condition()` holds; the virtual time it took (ms)."""
    for waited in range(limit_ms + 1):
        if condition():
            return waited
        machine.advance(1)
    raise AssertionError(f"not within {limit_ms} ms")


def enable(machine, mode):
    axis = machine.axis(0)
    axis.mode = mode
    axis.control_word = SHUTDOWN
    advance_until(machine, lambda: axis.state == "READY_TO_SWITCH_ON", 10)
    axis.control_word = ENABLE_OPERATION
    advance_until(machine, lambda: axis.state == "OPERATION_ENABLED" and not axis.brake_engaged, 100)
    return axis


def test_enable_takes_t2_t3_t4_and_releases_the_brake(machine):
    axis = enable(machine, "pv")
    assert axis.status_word & 0x6F == 0x27 and axis.outputs.torque
    transitions = [t for t in values(machine.trace(0)["transition"]) if t != -1]
    assert transitions == [0, 1, 2, 3, 4]


def test_a_profile_position_move_arrives_with_target_reached(machine):
    axis = enable(machine, "pp")
    axis[0x6081] = 600     # profile velocity, rpm
    axis[0x6083] = 2000    # acceleration, rpm/s
    axis[0x6084] = 2000    # deceleration, rpm/s
    axis[0x607A] = 50000   # five revolutions
    axis.control_word = ENABLE_OPERATION | NEW_SET_POINT
    advance_until(machine, lambda: axis.status_word & SET_POINT_ACK, 5)
    axis.control_word = ENABLE_OPERATION
    took = advance_until(machine, lambda: axis.status_word & TARGET_REACHED, 5000)
    assert axis.position == 50000 and axis.velocity_rpm == 0
    # 600 rpm is 10 revolutions a second, reached in 0.3 s over 1.5 revolutions: 0.3 s up, 2
    # revolutions at speed (0.2 s), 0.3 s down
    assert 790 <= took <= 820
    assert max(values(machine.trace(0)["velocity_rpm"])) == 600


def test_homing_method_3_homes_on_the_index_pulse_left_of_the_switch(machine):
    axis = enable(machine, "hm")
    axis[0x6098] = 3
    axis[0x607C] = 2500            # home offset: the pulse at 40,000 reads as 2,500
    axis[0x6099, 1] = 600          # search for the switch, rpm
    axis[0x6099, 2] = 60           # search for zero, rpm
    axis[0x609A] = 2000
    axis.control_word = ENABLE_OPERATION | NEW_SET_POINT
    done = HOMING_ATTAINED | TARGET_REACHED
    advance_until(machine, lambda: axis.status_word & done == done, 10000)
    assert axis.homing_phase == "homing attained"
    assert axis.position == 2500 and axis.velocity_rpm == 0


def test_a_fault_stops_the_drive_and_a_reset_brings_it_back(machine):
    axis = enable(machine, "pv")
    axis[0x60FF] = 1000
    machine.advance(1500)
    assert axis.velocity_rpm == 1000
    axis.inject_fault(0x4310)      # an over-temperature from outside
    advance_until(machine, lambda: axis.state == "FAULT", 1000)
    assert axis.error_code == 0x4310 and not axis.outputs.torque and axis.velocity_rpm == 0
    axis.control_word = FAULT_RESET
    machine.advance(5)
    assert axis.state == "FAULT"   # the cause is still there: the edge does nothing (S2)
    axis.clear_fault(0x4310)
    axis.control_word = 0
    machine.advance(1)
    axis.control_word = FAULT_RESET
    advance_until(machine, lambda: axis.state == "SWITCH_ON_DISABLED", 5)
    assert axis.error_code == 0
    enable(machine, "pv")
    assert axis.state == "OPERATION_ENABLED"


def test_a_csp_stream_is_followed_cycle_by_cycle_as_the_trace_shows(machine):
    axis = enable(machine, "csp")
    start = machine.cycle
    ramp = [20 * k for k in range(1, 2001)]   # 20 increments a ms: 120 rpm for 2 s
    machine.stream(0x607A, ramp)
    trace = machine.trace(0)
    demand = values(trace["position_demand"])[start:]
    position = values(trace["position"])[start:]
    times = values(trace["time_us"])[start:]
    assert len(demand) == len(ramp) and times[0] == start * 1000
    # A row shows what the cycle sampled: the set-point written before cycle k is the demand the
    # next row samples, and the shaft reaches it within the cycle.
    assert demand[1:] == ramp[:-1] and position[1:] == ramp[:-1]
    assert set(values(trace["state"])[start:]) == {"OPERATION_ENABLED"}
    assert all(v == pytest.approx(120) for v in values(trace["velocity_rpm"])[start + 2:])
    assert axis.following_error == 0 and axis.position == ramp[-1]
