"""cia402.sim.Machine and Axis: virtual drives on virtual time, objects by index, faults, STO."""
import threading

import pytest

import cia402
from cia402 import sim


def as_list(column):
    return column.tolist() if hasattr(column, "tolist") else list(column)


def enable(m, mode=None):
    if mode is not None:
        m.write(0x6060, mode)
    m.write(0x6040, 0x06)
    m.advance(3)
    m.write(0x6040, 0x0F)
    m.advance(60)  # past the brake's release


def test_a_machine_powers_up_in_switch_on_disabled_on_virtual_time():
    m = sim.Machine(axes=3)
    assert len(m) == 3 and m.cycle == 0 and m.time_us == 0 and m.cycle_us == 1000
    m.advance(10)
    assert m.cycle == 10 and m.time_us == 10_000
    assert as_list(m.states()) == ["SWITCH_ON_DISABLED"] * 3
    assert m.profile.name == "cia402" and m.threads == 1


def test_every_axis_enables_and_follows_its_velocity_set_point():
    m = sim.Machine(axes=4)
    enable(m)
    assert as_list(m.states()) == ["OPERATION_ENABLED"] * 4
    m.write(0x60FF, [100, 200, -300, 0])
    m.advance(1000)  # 1000 rpm/s: 300 rpm within 0.3 s
    assert as_list(m.read(0x606C)) == [100, 200, -300, 0]
    assert m.axis(2).velocity_rpm == -300.0 and m[2].outputs.torque


def test_objects_by_index_and_sub_index_on_one_axis():
    m = sim.Machine(axes=2)
    a = m.axis(1)
    a[0x6060] = 8
    a.write(0x6099, 700, sub=1)
    a[0x6099, 2] = 70
    m.step()
    assert a.read(0x6061) == 8 and a.mode == 8 and a[0x6099, 1] == 700 and a.read(0x6099, 2) == 70
    assert m.axis(0).mode == 3  # the other axis is untouched
    a.mode = "pp"
    m.step()
    assert a.mode == 1 and a.index == 1 and a.machine is m


def test_a_refused_write_raises_its_abort_code_and_changes_nothing():
    m = sim.Machine(axes=3)
    a = m.axis(0)
    with pytest.raises(cia402.SdoError) as refused:
        a[0x6060] = 2  # velocity mode (vl): not supported
    assert refused.value.code == 0x06090030 and a[0x6060] == 3
    with pytest.raises(cia402.SdoError) as refused:
        a[0x6041] = 0
    assert refused.value.code == 0x06010002
    with pytest.raises(cia402.SdoError) as refused:
        a[0x1234] = 0
    assert refused.value.code == 0x06020000
    with pytest.raises(cia402.SdoError) as refused:
        m.write(0x6083, [500, 0, 700])  # a ramp of 0 rpm/s would never end
    assert refused.value.code == 0x06090032
    assert as_list(m.read(0x6083)) == [1000, 1000, 1000]  # not even axis 0 took its value


def test_a_write_takes_one_value_or_one_per_axis():
    m = sim.Machine(axes=3)
    with pytest.raises(cia402.ArgumentError):
        m.write(0x6083, [1, 2])
    with pytest.raises(cia402.ArgumentError):
        m.write(0x6083, "fast")
    with pytest.raises(cia402.ArgumentError):
        m.axis(3)
    with pytest.raises(cia402.ArgumentError):
        m.axis(0)[0x6083] = 1.5


def test_an_injected_fault_then_its_clearing_and_a_reset():
    m = sim.Machine(axes=2)
    enable(m)
    a = m.axis(0)
    assert a.inject_fault(0x2310, error_class=2)
    m.advance(200)
    assert (a.state, a.error_code, a.fault_cause) == ("FAULT", 0x2310, 0x2310)
    assert m.axis(1).state == "OPERATION_ENABLED"
    assert a.clear_fault(0x2310) and not a.clear_fault(0x2310)
    a.control_word = 0x80
    m.advance(2)
    assert a.state == "SWITCH_ON_DISABLED" and a.control_word == 0x80


def test_sto_and_the_dc_link():
    m = sim.Machine(axes=1)
    enable(m)
    a = m.axis(0)
    a.sto = True
    m.step()
    assert a.sto and not a.outputs.torque and a.state != "OPERATION_ENABLED"
    b = sim.Machine(axes=1).axis(0)
    b.dc_link = False
    b.machine.advance(5)
    assert not b.dc_link and not b.status_word & 0x0010
    b.connection_lost = True
    assert b.connection_lost


def test_advance_takes_whole_cycles_of_the_plant():
    m = sim.Machine(plant={"cycle_us": 250})
    m.advance(0.25)
    m.advance(1)
    assert m.cycle == 5 and m.time_us == 1250
    with pytest.raises(cia402.ArgumentError, match="whole number"):
        m.advance(0.1)
    with pytest.raises(cia402.ArgumentError):
        m.advance(-1)
    m.step(3)
    assert m.cycle == 8


def test_the_plant_takes_plant_configs_keys_and_refuses_others():
    m = sim.Machine(plant={"brake_fitted": False, "home_switch_position": None, "load_permille": -20})
    assert m.plant["brake_fitted"] is False and m.plant["home_switch_position"] is None
    assert m.plant["load_permille"] == -20 and m.plant["cycle_us"] == 1000
    with pytest.raises(cia402.ArgumentError, match="unknown plant key 'cycle'.*cycle_us"):
        sim.Machine(plant={"cycle": 1000})
    with pytest.raises(cia402.ArgumentError, match="plant refused: cycle"):
        sim.Machine(plant={"cycle_us": 0})
    with pytest.raises(cia402.ArgumentError, match="True or False"):
        sim.Machine(plant={"brake_fitted": 1})
    with pytest.raises(cia402.ArgumentError):
        sim.Machine(plant={"cycle_us": -1})
    with pytest.raises(cia402.ArgumentError):
        sim.Machine(axes=0)


def test_a_machine_on_two_threads_steps_every_axis_as_one_thread_does():
    results = []
    for threads in (1, 2):
        m = sim.Machine(axes=200, threads=threads)
        enable(m, mode=8)
        m.stream(0x607A, [[c * 10 + i for i in range(200)] for c in range(300)])
        m.axis(7).inject_fault(0x1000)
        m.advance(50)
        results.append((as_list(m.read(0x6064)), as_list(m.states())))
    assert results[0] == results[1]


def test_stream_writes_a_row_before_each_cycle_and_checks_every_value_first():
    m = sim.Machine(axes=2, trace=[1])
    enable(m, mode=8)
    start = m.cycle
    m.stream(0x607A, [5 * k for k in range(1, 101)])  # one value for both axes each cycle
    assert m.cycle == start + 100
    assert m.axis(0)[0x607A] == 500 and m.axis(1).position_demand == 500
    with pytest.raises(cia402.SdoError) as refused:
        m.stream(0x6083, [[10, 10], [10, 0]])
    assert refused.value.code == 0x06090032 and m.cycle == start + 100
    with pytest.raises(cia402.ArgumentError):
        m.stream(0x607A, [[1, 2, 3]])
    trace = m.trace(1)
    assert len(trace) == m.cycle and as_list(trace["time_us"])[-1] == (m.cycle - 1) * 1000


def test_a_machine_in_use_on_another_thread_is_refused_and_the_gil_is_free_meanwhile():
    m = sim.Machine(axes=2000)
    enable(m)
    done = threading.Event()
    worker = threading.Thread(target=lambda: (m.advance(4000), done.set()))
    refusals = 0
    worker.start()
    while not done.is_set():
        try:
            m.axis(0).state
        except cia402.BusyError:
            refusals += 1
    worker.join()
    assert refusals > 0  # this thread ran while the machine stepped: the GIL was released
    assert m.cycle == 63 + 4000


def test_homing_phase_and_the_digital_inputs():
    m = sim.Machine()
    a = m.axis(0)
    assert a.homing_phase == "not started" and a.digital_inputs & 0x10000  # an index pulse at 0
    assert a.brake_engaged and a.following_error == 0 and a.torque_permille == 0
    assert repr(a) == "cia402.sim.Axis(0, state='START')"  # not stepped yet: T0 comes first
    assert repr(m) == "cia402.sim.Machine(axes=1, profile='cia402', time_us=0)"


def test_a_machine_iterates_its_axes_and_a_trace_its_columns():
    m = sim.Machine(axes=3, trace=[0])
    assert [a.index for a in m] == [0, 1, 2]
    m.advance(2)
    t = m.trace(0)
    assert list(t) == list(t.columns) and dict(zip(t, (t[c] for c in t)))["time_us"][1] == 1000
