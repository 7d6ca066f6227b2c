"""`cia402 bus` seen by a third-party CANopen client: python-can's socketcand interface sends raw
NMT, SDO and PDO frames and reads heartbeats, EMCY and PDOs. Expected values are CiA 301 / CiA 402
numbers written out here, not taken from our code."""
import configparser
import os
import socket
import subprocess
import time

import can

NODE = 1


def send(bus, cob_id, data):
    bus.send(can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False))


def wait_for(bus, match, timeout=2.0):
    """The first received frame for which match(msg) is true, or None."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        msg = bus.recv(timeout=max(0.0, end - time.monotonic()))
        if msg is not None and match(msg):
            return msg
    return None


def sdo_upload_expedited(bus, node, index, sub):
    send(bus, 0x600 + node, [0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])
    msg = wait_for(bus, lambda m: m.arbitration_id == 0x580 + node)
    assert msg is not None, "no SDO answer"
    assert msg.data[0] & 0xE0 == 0x40, "SDO abort 0x%08X" % int.from_bytes(msg.data[4:8], "little")
    size = 4 - ((msg.data[0] >> 2) & 3)
    return int.from_bytes(msg.data[4:4 + size], "little")


def sdo_download(bus, node, index, sub, value, size):
    command = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    send(bus, 0x600 + node, [command, index & 0xFF, index >> 8, sub]
         + list(value.to_bytes(4, "little")))
    msg = wait_for(bus, lambda m: m.arbitration_id == 0x580 + node)
    assert msg is not None, "no SDO answer"
    return msg


def wait_for_state(bus, state, timeout=3.0):
    """The first status word TPDO1 (0x6041, sent on change) of NODE in `state`, or None."""
    return wait_for(bus, lambda m: m.arbitration_id == 0x180 + NODE and len(m.data) >= 2
                    and status_state(int.from_bytes(m.data[0:2], "little")) == state, timeout)


# CiA 402 states by their status word bits (mask, value), as the standard's table gives them.
STATES = ((0x4F, 0x40, "SWITCH_ON_DISABLED"), (0x6F, 0x21, "READY_TO_SWITCH_ON"), (0x6F, 0x23, "SWITCHED_ON"),
          (0x6F, 0x27, "OPERATION_ENABLED"), (0x6F, 0x07, "QUICK_STOP_ACTIVE"),
          (0x4F, 0x0F, "FAULT_REACTION_ACTIVE"), (0x4F, 0x08, "FAULT"))


def status_state(word):
    """CiA 402 state from a status word (masks 0x4F / 0x6F)."""
    return next((name for mask, value, name in STATES if word & mask == value), "NOT_READY_TO_SWITCH_ON")


def test_sdo_upload_reads_device_type_of_a_cia402_servo(client):
    assert sdo_upload_expedited(client, NODE, 0x1000, 0) == 0x00020192
    assert sdo_upload_expedited(client, 2, 0x1018, 4) == 2  # serial number = node-ID


def test_sdo_segmented_upload_reads_the_device_name(client):
    send(client, 0x601, [0x40, 0x08, 0x10, 0, 0, 0, 0, 0])
    first = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert first.data[0] == 0x41
    size = int.from_bytes(first.data[4:8], "little")
    text, toggle = b"", 0
    while True:
        send(client, 0x601, [0x60 | (toggle << 4), 0, 0, 0, 0, 0, 0, 0])
        seg = wait_for(client, lambda m: m.arbitration_id == 0x581)
        assert seg.data[0] & 0x10 == toggle << 4
        text += bytes(seg.data[1:8 - ((seg.data[0] >> 1) & 7)])
        toggle ^= 1
        if seg.data[0] & 1:
            break
    assert size == len(text)
    assert text == b"cia402 virtual drive"


def crc16_ccitt(data):
    """CiA 301's block CRC (CRC-16/XMODEM), written out here."""
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021 if crc & 0x8000 else crc << 1) & 0xFFFF
    return crc


def test_sdo_block_upload_and_download_with_crc(client):
    # Block upload of 0x1008 in blocks of 2 segments, CRC asked for.
    send(client, 0x601, [0xA4, 0x08, 0x10, 0, 2, 0, 0, 0])
    first = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert first.data[0] == 0xC6, "block upload initiate response: %02X" % first.data[0]
    size = int.from_bytes(first.data[4:8], "little")
    send(client, 0x601, [0xA3, 0, 0, 0, 0, 0, 0, 0])
    data, done = b"", False
    while not done:
        got = 0
        while True:
            seg = wait_for(client, lambda m: m.arbitration_id == 0x581)
            assert seg is not None, "a block segment did not come"
            assert seg.data[0] & 0x7F == got + 1
            got += 1
            data += bytes(seg.data[1:8])
            if seg.data[0] & 0x80:
                done = True
                break
            if got == 2:
                break
        send(client, 0x601, [0xA2, got, 2, 0, 0, 0, 0, 0])
    end = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert end.data[0] & 0xE3 == 0xC1, "block upload end: %02X" % end.data[0]
    data = data[:len(data) - ((end.data[0] >> 2) & 7)]
    send(client, 0x601, [0xA1, 0, 0, 0, 0, 0, 0, 0])
    assert data == b"cia402 virtual drive" and size == len(data)
    assert int.from_bytes(end.data[1:3], "little") == crc16_ccitt(data)
    # Block download of 12 bytes to 0x2000 with the CRC, then read back by a segmented upload.
    text = b"block write!"
    send(client, 0x601, [0xC6, 0x00, 0x20, 0] + list(len(text).to_bytes(4, "little")))
    answer = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert answer.data[0] == 0xA4, "block download initiate response: %02X" % answer.data[0]
    send(client, 0x601, [0x01] + list(text[0:7]))
    send(client, 0x601, [0x82] + list(text[7:12]) + [0, 0])
    ack = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert ack.data[0] == 0xA2 and ack.data[1] == 2, list(ack.data)
    crc = crc16_ccitt(text)
    send(client, 0x601, [0xC1 | (2 << 2), crc & 0xFF, crc >> 8, 0, 0, 0, 0, 0])
    assert wait_for(client, lambda m: m.arbitration_id == 0x581).data[0] == 0xA1
    send(client, 0x601, [0x40, 0x00, 0x20, 0, 0, 0, 0, 0])
    first = wait_for(client, lambda m: m.arbitration_id == 0x581)
    assert first.data[0] == 0x41 and int.from_bytes(first.data[4:8], "little") == len(text)


def test_sdo_abort_for_an_unknown_object(client):
    msg = sdo_download(client, NODE, 0x2FFF, 0, 1, 1)
    assert msg.data[0] == 0x80
    assert int.from_bytes(msg.data[4:8], "little") == 0x06020000


def test_heartbeat_follows_nmt_states(client):
    assert sdo_download(client, NODE, 0x1017, 0, 50, 2).data[0] == 0x60
    hb = wait_for(client, lambda m: m.arbitration_id == 0x701)
    assert hb is not None and list(hb.data) == [0x7F]  # pre-operational
    send(client, 0x000, [0x01, NODE])  # NMT start
    hb = wait_for(client, lambda m: m.arbitration_id == 0x701 and m.data[0] == 0x05)
    assert hb is not None
    send(client, 0x000, [0x02, NODE])  # NMT stop
    assert wait_for(client, lambda m: m.arbitration_id == 0x701 and m.data[0] == 0x04) is not None


def test_reset_node_sends_boot_up(client):
    send(client, 0x000, [0x81, 2])
    boot = wait_for(client, lambda m: m.arbitration_id == 0x702)
    assert boot is not None and list(boot.data) == [0x00]


def test_drive_reaches_operation_enabled_over_pdos(client):
    log = []
    send(client, 0x000, [0x01, NODE])  # NMT start: TPDO1 (0x6041) comes at once, then on change

    def status(m):
        return m.arbitration_id == 0x181 and len(m.data) == 2

    msg = wait_for(client, status)
    assert msg is not None
    log.append(status_state(int.from_bytes(msg.data, "little")))
    send(client, 0x201, (0x0006).to_bytes(2, "little"))  # Shutdown (T2)
    # Enable operation waits for Shutdown to act: a drive sees the last RPDO before its cycle, so a
    # word sent before it has stepped would replace the one before (a held-up bus server does that).
    assert wait_for_state(client, "READY_TO_SWITCH_ON") is not None, log
    log.append("READY_TO_SWITCH_ON")
    send(client, 0x201, (0x000F).to_bytes(2, "little"))  # Enable operation (T3, T4)
    deadline = time.monotonic() + 3
    state = log[-1]
    while state != "OPERATION_ENABLED" and time.monotonic() < deadline:
        msg = wait_for(client, status, timeout=0.5)
        if msg is not None:
            state = status_state(int.from_bytes(msg.data, "little"))
            log.append(state)
    assert state == "OPERATION_ENABLED", log
    assert "READY_TO_SWITCH_ON" in log
    assert sdo_upload_expedited(client, NODE, 0x6041, 0) & 0x6F == 0x27
    # Velocity through RPDO4 (0x6040 + 0x60FF), read back through TPDO4 (0x6041 + 0x606C).
    send(client, 0x501, list((0x000F).to_bytes(2, "little")) + list((100).to_bytes(4, "little", signed=True)))
    fast = wait_for(client, lambda m: m.arbitration_id == 0x481
                    and int.from_bytes(m.data[2:6], "little", signed=True) >= 90, timeout=3)
    assert fast is not None


def test_tpdo_timing_a_standard_master_can_rely_on(client):
    """CiA 301 0x1800.. sub 3 (inhibit, 100 us) and sub 5 (event timer, ms) as a master reads them,
    then measured: each TPDO at least once a second while nothing changes (TPDO1 and TPDO2, the
    status word's, every 100 ms), TPDO4 (status word + velocity) at most every 10 ms while the
    drive ramps."""
    send(client, 0x000, [0x01, NODE])
    for n, event_timer_ms in ((0, 100), (1, 100), (3, 1000)):  # PDO 3 is synchronous: sent on SYNC
        assert sdo_upload_expedited(client, NODE, 0x1800 + n, 5) == event_timer_ms, "TPDO%d event timer" % (n + 1)
    assert sdo_upload_expedited(client, NODE, 0x1803, 3) == 100  # 10 ms
    # Idle: every TPDO still comes, from the event timer.
    seen = {}
    end = time.monotonic() + 2.5
    while time.monotonic() < end:
        msg = client.recv(timeout=0.1)
        if msg is not None and msg.arbitration_id in (0x181, 0x281, 0x481):
            seen[msg.arbitration_id] = seen.get(msg.arbitration_id, 0) + 1
    assert all(seen.get(i, 0) >= 2 for i in (0x181, 0x281, 0x481)), seen
    assert seen[0x181] >= 15 and seen[0x281] >= 15, seen  # every 100 ms for 2.5 s
    # Ramping from 0 to 3000 rpm (3 s at the default 1000 rpm/s): count TPDO4 over one second.
    send(client, 0x201, [0x06, 0x00])
    assert wait_for_state(client, "READY_TO_SWITCH_ON") is not None
    send(client, 0x201, [0x0F, 0x00])
    time.sleep(0.1)
    send(client, 0x501, [0x0F, 0x00] + list((3000).to_bytes(4, "little", signed=True)))
    time.sleep(0.3)
    while client.recv(timeout=0) is not None:
        pass  # what queued up while sleeping is not part of the measured second
    stamps = []
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        msg = client.recv(timeout=0.1)
        if msg is not None and msg.arbitration_id == 0x481:
            stamps.append(msg.timestamp)
    assert 50 <= len(stamps) <= 105, len(stamps)
    send(client, 0x201, [0x00, 0x00])


def test_modes_of_operation_round_trip_and_display_in_tpdo2(client):
    """0x6060 written over SDO, 0x6061 read back at once and carried by TPDO2 (0x6041 + 0x6061)."""
    send(client, 0x000, [0x01, NODE])
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) == 3  # profile velocity
    answer = sdo_download(client, NODE, 0x6060, 0, 3, 1)
    assert answer.data[0] == 0x60, "0x6060 = 3 refused"
    assert sdo_upload_expedited(client, NODE, 0x6060, 0) == 3
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) == 3
    tpdo2 = wait_for(client, lambda m: m.arbitration_id == 0x281 and len(m.data) == 3, timeout=2)
    assert tpdo2 is not None and tpdo2.data[2] == 3
    # A mode this drive does not have is refused with an abort, and 0x6061 stays.
    refused = sdo_download(client, NODE, 0x6060, 0, 2, 1)
    assert refused.data[0] == 0x80, "0x6060 = 2 (velocity mode, not offered) accepted"
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) == 3


def test_fault_sends_emcy_and_fault_reset_sends_emcy_0000(client):
    send(client, 0x000, [0x01, NODE])
    assert sdo_download(client, NODE, 0x2001, 0, 0x2310, 2).data[0] == 0x60  # inject over-current
    emcy = wait_for(client, lambda m: m.arbitration_id == 0x081)
    assert emcy is not None
    assert int.from_bytes(emcy.data[0:2], "little") == 0x2310
    assert emcy.data[2] & 0x03 == 0x03  # generic + current
    assert wait_for(client, lambda m: m.arbitration_id == 0x181
                    and status_state(int.from_bytes(m.data[0:2], "little")) == "FAULT") is not None
    assert sdo_download(client, NODE, 0x2001, 0, 0, 2).data[0] == 0x60  # cause gone
    send(client, 0x201, [0x00, 0x00])
    time.sleep(0.02)
    send(client, 0x201, [0x80, 0x00])  # fault reset edge (T15)
    reset = wait_for(client, lambda m: m.arbitration_id == 0x081)
    assert reset is not None and int.from_bytes(reset.data[0:2], "little") == 0x0000


def test_two_clients_see_each_others_frames_and_bad_input_does_not_stop_the_bus(bus_server, client):
    raw = socket.create_connection(("127.0.0.1", bus_server["port"]), timeout=2)
    assert raw.recv(64) == b"< hi >"
    raw.sendall(b"< open can0 >")
    assert raw.recv(64) == b"< ok >"
    raw.sendall(b"< bogus >< send 12X 1 00 >< " + b"x" * 400 + b" >")
    got = b""
    end = time.monotonic() + 2
    while got.count(b"< error") < 3 and time.monotonic() < end:
        got += raw.recv(4096)
    assert got.count(b"< error") == 3, got
    raw.sendall(b"< send 7E4 2 de ad >")
    msg = wait_for(client, lambda m: m.arbitration_id == 0x7E4)
    assert msg is not None and bytes(msg.data) == b"\xde\xad"
    raw.close()
    assert sdo_upload_expedited(client, NODE, 0x1000, 0) == 0x00020192


def test_sigterm_stops_the_bus_cleanly(bus_server):
    bus_server["proc"].send_signal(15)
    bus_server["proc"].wait(timeout=5)
    assert bus_server["proc"].returncode == 0


def test_eds_loads_with_configparser_and_lists_are_consistent():
    text = subprocess.run([os.environ["CIA402_BIN"], "eds"], check=True, capture_output=True,
                          text=True).stdout
    eds = configparser.RawConfigParser()
    eds.optionxform = str
    eds.read_string(text)
    listed = set()
    for group in ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects"):
        count = int(eds[group]["SupportedObjects"], 0)
        entries = [int(eds[group][str(i)], 0) for i in range(1, count + 1)]
        assert len(entries) == count
        for index in entries:
            name = "%04X" % index
            assert name in eds, name
            obj = eds[name]
            assert int(obj["ObjectType"], 0) in (7, 8, 9)
            if int(obj["ObjectType"], 0) != 7:
                subs = [s for s in eds.sections() if s.startswith(name + "sub")]
                assert len(subs) == int(obj["SubNumber"], 0)
            listed.add(index)
    for mandatory in (0x1000, 0x1001, 0x1018):
        assert mandatory in [int(eds["MandatoryObjects"][k], 0)
                             for k in eds["MandatoryObjects"] if k != "SupportedObjects"]
    assert eds["1000"]["DefaultValue"] == "0x00020192"
    assert eds["1800sub1"]["DefaultValue"] == "$NODEID+0x180"
    assert eds["2001"]["AccessType"] == "wo"
    sections = {int(s, 16) for s in eds.sections() if len(s) == 4 and all(c in "0123456789ABCDEF" for c in s)}
    assert sections == listed
