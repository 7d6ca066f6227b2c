"""cia402.canopen.VirtualBus: the virtual CAN bus with its drives in process, on virtual time and on
wall time, through its ports and through python-can (Debian's python3-can). SDO frames are
CiA 301's (§7.2.4.3), written out here; values are the drive's (0x1000 = 0x00020192: a CiA 402
servo drive)."""
import threading
import time

import pytest

import cia402
from cia402.canopen import VirtualBus

DEVICE_TYPE = 0x00020192


def upload_request(index, sub=0):
    return bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])


def test_a_port_reads_an_object_on_virtual_time_only_as_time_is_advanced():
    bus = VirtualBus(nodes=[3], virtual_time=True)
    port = bus.attach()
    port.send(0x603, upload_request(0x1000))
    assert port.recv(0) is None, "nothing moves on virtual time before advance()"
    bus.advance(2)
    got = port.recv(0)
    assert got is not None
    cob_id, data, extended, remote, dlc = got
    assert (cob_id, extended, remote, dlc) == (0x583, False, False, 8)
    assert data[0] == 0x43 and int.from_bytes(data[4:8], "little") == DEVICE_TYPE
    assert bus.time_ms == 2.0


def test_nodes_take_a_count_or_node_ids_and_refuse_duplicates_and_bad_ids():
    assert VirtualBus(nodes=3, virtual_time=True).nodes == [1, 2, 3]
    assert VirtualBus(nodes=(5, 9), virtual_time=True).nodes == [5, 9]
    for bad in ([1, 1], [0], [128], 0, "1", []):
        with pytest.raises(cia402.ArgumentError):
            VirtualBus(nodes=bad, virtual_time=True)
    with pytest.raises(cia402.ProfileError):
        VirtualBus(profile="no-such-profile", virtual_time=True)


def test_advance_is_refused_on_wall_time_and_wall_time_moves_by_itself():
    with VirtualBus() as bus:
        with pytest.raises(cia402.ArgumentError):
            bus.advance(1)
        start = bus.time_ms
        end = time.monotonic() + 5
        while bus.time_ms - start < 20 and time.monotonic() < end:
            time.sleep(0.005)
        assert bus.time_ms - start >= 20, "the drives' time follows the wall clock"
    assert bus.closed
    stopped = bus.time_ms
    time.sleep(0.02)
    assert bus.time_ms == stopped, "a closed bus steps no more"


def test_the_eds_is_the_nodes_own_with_its_node_id():
    bus = VirtualBus(nodes=[7], profile="cia402", virtual_time=True)
    eds = bus.eds(7)
    assert "[1000]" in eds and "[6041]" in eds and "[1401]" in eds
    assert "NodeID=7" in eds
    with pytest.raises(cia402.ArgumentError):
        bus.eds(1)


def test_a_port_refuses_frames_can_cannot_carry():
    port = VirtualBus(virtual_time=True).attach()
    with pytest.raises(cia402.ArgumentError):
        port.send(0x800, b"")
    with pytest.raises(cia402.ArgumentError):
        port.send(0x601, bytes(9))
    port.close()
    assert port.recv(0) is None
    with pytest.raises(cia402.ArgumentError):
        port.send(0x601, upload_request(0x1000))


def test_a_recv_waiting_on_one_thread_gets_a_frame_sent_on_another():
    bus = VirtualBus(virtual_time=True)
    a, b = bus.attach(), bus.attach()
    got = []
    waiter = threading.Thread(target=lambda: got.append(b.recv(5)))
    waiter.start()
    time.sleep(0.05)
    a.send(0x123, b"\x01\x02")
    waiter.join(5)
    assert got and got[0][:2] == (0x123, b"\x01\x02")


try:
    import can
except ImportError:  # Debian's python3-can
    can = None
needs_python_can = pytest.mark.skipif(can is None, reason="python-can (python3-can) is not installed")


@needs_python_can
def test_python_can_reads_the_device_type_by_sdo_on_wall_time():
    with VirtualBus(nodes=[2]) as bus:
        with bus.python_can_bus() as can_bus:
            assert isinstance(can_bus, can.BusABC)
            can_bus.send(can.Message(arbitration_id=0x602, data=upload_request(0x1000), is_extended_id=False))
            reply = None
            end = time.monotonic() + 2
            while reply is None and time.monotonic() < end:
                msg = can_bus.recv(timeout=0.5)
                if msg is not None and msg.arbitration_id == 0x582:
                    reply = msg
            assert reply is not None, "no SDO answer within 2 s"
            assert int.from_bytes(reply.data[4:8], "little") == DEVICE_TYPE


@needs_python_can
def test_python_can_sees_what_another_python_can_bus_sends_and_filters_in_python():
    bus = VirtualBus(virtual_time=True)
    a = bus.python_can_bus()
    b = bus.python_can_bus(can_filters=[{"can_id": 0x080, "can_mask": 0x7FF}])
    a.send(can.Message(arbitration_id=0x7E5, data=[1], is_extended_id=False))
    a.send(can.Message(arbitration_id=0x080, data=[], is_extended_id=False))
    msg = b.recv(timeout=1)
    assert msg is not None and msg.arbitration_id == 0x080 and msg.is_rx
    assert b.recv(timeout=0) is None
    a.shutdown()
    b.shutdown()


@needs_python_can
def test_a_python_can_notifier_and_a_log_writer_run_on_the_bus(tmp_path):
    """python-can's Notifier thread and its log writers work on the bus as on any other."""
    path = tmp_path / "bus.log"
    with VirtualBus() as bus, bus.python_can_bus() as can_bus:
        writer = can.CanutilsLogWriter(str(path), channel="can0")
        seen = set()
        notifier = can.Notifier(can_bus, [writer, lambda m: seen.add(m.arbitration_id)], timeout=0.1)
        can_bus.send(can.Message(arbitration_id=0x000, data=[0x01, 0x01], is_extended_id=False))  # NMT start
        end = time.monotonic() + 5  # the drive's TPDOs go out on entering OPERATIONAL
        while not {0x181, 0x281} <= seen and time.monotonic() < end:
            time.sleep(0.01)
        notifier.stop()
        writer.stop()
    ids = {m.arbitration_id for m in can.CanutilsLogReader(str(path))}
    assert 0x181 in ids and 0x281 in ids
