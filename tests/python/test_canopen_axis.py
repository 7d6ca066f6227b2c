"""cia402.canopen.Axis: the project's master (the axis session of `cia402 master`) over its CAN link
on a VirtualBus, from Python: requests that wait for their end, results as dicts, refusals as
SdoError (with the abort code) or AxisError. Object numbers are CiA 402-2's; abort codes CiA 301's."""
import pytest

import cia402
from cia402.canopen import VirtualBus

NODE = 4


@pytest.fixture
def axis():
    with VirtualBus(nodes=[NODE], virtual_time=True) as bus:
        a = bus.axis(NODE)
        yield a
        a.close()


def test_enable_move_home_and_velocity_end_where_they_were_asked_to(axis):
    assert axis.enable()["state"] == "OPERATION_ENABLED"
    assert axis.mode("pp")["mode"] == 1
    moved = axis.move(10000, velocity=1000)
    assert moved["position"] == 10000 and moved["state"] == "OPERATION_ENABLED"
    assert axis.move(-2500, relative=True)["position"] == 7500
    homed = axis.home(37)
    assert homed["mode"] == 6 and homed["position"] == 0
    assert homed["status_word"] & (1 << 12) and homed["status_word"] & (1 << 10)
    assert axis.velocity(500)["velocity"] == 500
    assert axis.state == "OPERATION_ENABLED"
    assert axis.disable()["state"] == "SWITCH_ON_DISABLED"


def test_a_request_on_virtual_time_advances_the_bus_itself():
    with VirtualBus(nodes=[NODE], virtual_time=True) as bus:
        a = bus.axis(NODE)
        assert bus.time_ms == 0
        a.enable()
        assert bus.time_ms > 0
        assert a.mode(6)["mode"] == 6


def test_sdo_read_gives_each_object_as_its_type_says(axis):
    assert axis.sdo_read(0x1000) == 0x00020192
    assert axis.sdo_read(0x1008) == "cia402 virtual drive"
    assert axis.sdo_read(0x1018, 4) == NODE  # serial number = node-ID
    axis.sdo_write(0x2000, "bench 7")
    assert axis.sdo_read(0x2000) == "bench 7"


def test_a_refused_object_raises_sdoerror_with_its_abort_code_and_changes_nothing(axis):
    with pytest.raises(cia402.SdoError) as e:
        axis.sdo_read(0x2005)
    assert e.value.code == 0x06020000 and e.value.index == 0x2005 and e.value.sub == 0
    assert e.value.text == cia402.sdo_abort_text(0x06020000)
    with pytest.raises(cia402.SdoError) as e:
        axis.sdo_read(0x2001)  # fault injection is write-only
    assert e.value.code == 0x06010001
    before = axis.sdo_read(0x6060)
    with pytest.raises(cia402.SdoError) as e:
        axis.sdo_write(0x6060, 300)
    assert e.value.code == 0x06090031
    assert axis.sdo_read(0x6060) == before


def test_a_type_given_must_agree_with_the_one_known_and_be_a_cia301_type(axis):
    with pytest.raises(cia402.ArgumentError):
        axis.sdo_write(0x6060, 1, type="unsigned32")  # 0x6060 is INTEGER8
    with pytest.raises(cia402.ArgumentError):
        axis.sdo_write(0x2001, 0, type="uint16")
    axis.sdo_write(0x6060, 3, type="integer8")
    assert axis.sdo_read(0x6060) == 3
    with pytest.raises(cia402.ArgumentError):
        axis.mode("warp")


def test_a_fault_raises_axiserror_with_its_code_and_a_reset_recovers(axis):
    axis.enable()
    axis.sdo_write(0x2001, 0x2310, type="unsigned16")  # fault injection: continuous over-current
    with pytest.raises(cia402.AxisError) as e:
        axis.move(1000)
    assert e.value.error_code == 0x2310
    assert e.value.state in ("FAULT", "FAULT_REACTION_ACTIVE")
    assert "0x2310" in str(e.value)
    axis.sdo_write(0x2001, 0, type="unsigned16")
    assert axis.reset()["state"] == "SWITCH_ON_DISABLED"
    assert axis.enable()["state"] == "OPERATION_ENABLED"


def test_a_request_that_does_not_end_in_time_raises_axiserror(axis):
    axis.enable()
    with pytest.raises(cia402.AxisError, match="did not end within"):
        axis.move(10_000_000, velocity=10, timeout=0.05)


def test_an_axis_needs_a_node_on_the_bus_and_refuses_work_once_closed():
    with VirtualBus(nodes=[NODE], virtual_time=True) as bus:
        with pytest.raises(cia402.ArgumentError):
            bus.axis(NODE + 1)
        a = bus.axis(NODE)
        a.enable()
        a.close()
        assert a.closed
        with pytest.raises(cia402.ArgumentError):
            a.enable()


def test_the_master_runs_on_wall_time_too():
    with VirtualBus(nodes=[NODE]) as bus:
        a = bus.axis(NODE)
        assert a.enable()["state"] == "OPERATION_ENABLED"
        assert a.move(2000, velocity=3000)["position"] == 2000
        a.close()
