"""The operation modes of `cia402 bus` driven by a third-party CANopen client (python-can over
socketcand): modes switched by SDO and by RPDO2, a profile position move with the set-point
handshake, a homing run, and a cyclic synchronous position stream on SYNC with RPDO3 / TPDO3.
Object numbers, bits and PDO layouts are CiA 402-2's, written out here."""
import json
import os
import subprocess
import time

import pytest

from test_bus_python_can import NODE, send, wait_for, sdo_upload_expedited, sdo_download, status_state

SYNC = 0x080
RPDO1, RPDO2, RPDO3 = 0x200 + NODE, 0x300 + NODE, 0x400 + NODE
TPDO1, TPDO2, TPDO3 = 0x180 + NODE, 0x280 + NODE, 0x380 + NODE


def status_frames(m):
    return m.arbitration_id == TPDO1 and len(m.data) == 2


def wait_status(bus, predicate, timeout=5.0):
    """The first status word (TPDO1) for which predicate(word) holds, or None."""
    msg = wait_for(bus, lambda m: status_frames(m) and predicate(int.from_bytes(m.data, "little")), timeout)
    return None if msg is None else int.from_bytes(msg.data, "little")


def enable(bus):
    send(bus, 0x000, [0x01, NODE])  # NMT start
    send(bus, RPDO1, [0x06, 0x00])
    # 0x0F waits for 0x06 to act: the drive sees the last RPDO before its cycle (a held-up server).
    assert wait_status(bus, lambda w: status_state(w) == "READY_TO_SWITCH_ON", timeout=3) is not None
    send(bus, RPDO1, [0x0F, 0x00])
    word = wait_status(bus, lambda w: status_state(w) == "OPERATION_ENABLED")
    assert word is not None, "not enabled"
    time.sleep(0.1)  # the holding brake opens (30 ms)


def position_on_sync(bus):
    """Sends SYNC and returns 0x6064 from TPDO3 (0x6041 + 0x6064), sent on every SYNC."""
    while bus.recv(timeout=0) is not None:
        pass
    send(bus, SYNC, [])
    msg = wait_for(bus, lambda m: m.arbitration_id == TPDO3 and len(m.data) == 6, timeout=2)
    assert msg is not None, "no TPDO3 after SYNC"
    return int.from_bytes(msg.data[2:6], "little", signed=True)


def test_modes_switch_by_sdo_and_by_rpdo2(client):
    send(client, 0x000, [0x01, NODE])
    assert sdo_upload_expedited(client, NODE, 0x6502, 0) == 0x3AD  # pp, pv, tq, hm, csp, csv, cst
    # PDO 3 is synchronous (transmission type 1): RPDO3 at the next SYNC, TPDO3 on every SYNC.
    assert sdo_upload_expedited(client, NODE, 0x1402, 2) == 1
    assert sdo_upload_expedited(client, NODE, 0x1802, 2) == 1
    assert sdo_upload_expedited(client, NODE, 0x1602, 2) == 0x607A0020
    assert sdo_upload_expedited(client, NODE, 0x1A02, 2) == 0x60640020
    assert sdo_download(client, NODE, 0x6060, 0, 1, 1).data[0] == 0x60
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) in (1, 3)  # switched by the next cycle
    end = time.monotonic() + 2
    while sdo_upload_expedited(client, NODE, 0x6061, 0) != 1 and time.monotonic() < end:
        time.sleep(0.005)
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) == 1
    # RPDO2 = 0x6040 + 0x6060 starts not valid (COB-ID bit 31): a master that wants it makes it
    # valid. TPDO2 = 0x6041 + 0x6061 shows the switch.
    assert sdo_upload_expedited(client, NODE, 0x1401, 1) == 0x80000000 + RPDO2
    assert sdo_download(client, NODE, 0x1401, 1, RPDO2, 4).data[0] == 0x60
    send(client, RPDO2, [0x00, 0x00, 8])
    shown = wait_for(client, lambda m: m.arbitration_id == TPDO2 and len(m.data) == 3 and m.data[2] == 8, 2)
    assert shown is not None, "0x6061 did not show csp"
    refused = sdo_download(client, NODE, 0x6060, 0, 2, 1)
    assert refused.data[0] == 0x80 and int.from_bytes(refused.data[4:8], "little") == 0x06090030


def test_profile_position_move(client):
    send(client, 0x000, [0x01, NODE])
    assert sdo_download(client, NODE, 0x6060, 0, 1, 1).data[0] == 0x60
    assert sdo_download(client, NODE, 0x6081, 0, 600, 4).data[0] == 0x60  # profile velocity, rpm
    enable(client)
    assert sdo_download(client, NODE, 0x607A, 0, 20000, 4).data[0] == 0x60  # 2 revolutions
    send(client, RPDO1, [0x1F, 0x00])  # bit 4: new set-point
    assert wait_status(client, lambda w: w & 0x1000) is not None, "no set-point acknowledge (bit 12)"
    send(client, RPDO1, [0x0F, 0x00])
    assert wait_status(client, lambda w: (w & 0x1400) == 0x0400, timeout=5) is not None, "no target reached"
    assert position_on_sync(client) == 20000
    # Relative (bit 6): adds to the last target.
    assert sdo_download(client, NODE, 0x607A, 0, (-5000) & 0xFFFFFFFF, 4).data[0] == 0x60
    send(client, RPDO1, [0x5F, 0x00])
    assert wait_status(client, lambda w: w & 0x1000) is not None
    send(client, RPDO1, [0x4F, 0x00])
    assert wait_status(client, lambda w: (w & 0x1400) == 0x0400, timeout=5) is not None
    assert position_on_sync(client) == 15000


@pytest.mark.parametrize("method", [37, 3])
def test_homing_run(client, method):
    """37: home on the current position; 3: the home switch (positive side), then the index pulse."""
    send(client, 0x000, [0x01, NODE])
    assert sdo_download(client, NODE, 0x6060, 0, 6, 1).data[0] == 0x60
    assert sdo_download(client, NODE, 0x6098, 0, method, 1).data[0] == 0x60
    assert sdo_download(client, NODE, 0x607C, 0, 4321, 4).data[0] == 0x60
    enable(client)
    send(client, RPDO1, [0x1F, 0x00])  # bit 4: homing operation start
    ended = wait_status(client, lambda w: (w & 0x2000) or (w & 0x1400) == 0x1400, timeout=20)
    assert ended is not None, "homing did not end"
    assert ended & 0x3400 == 0x1400, "homing error (bit 13): 0x%04X" % ended
    assert position_on_sync(client) == 4321
    assert sdo_upload_expedited(client, NODE, 0x6064, 0) == 4321


def test_cyclic_synchronous_position_stream(client):
    send(client, 0x000, [0x01, NODE])
    assert sdo_download(client, NODE, 0x1401, 1, RPDO2, 4).data[0] == 0x60  # RPDO2 made valid
    send(client, RPDO2, [0x00, 0x00, 8])  # mode 8 by PDO
    time.sleep(0.05)
    assert sdo_upload_expedited(client, NODE, 0x6061, 0) == 8
    enable(client)
    start = position_on_sync(client)
    worst = 0
    target = start
    for k in range(1, 41):
        target = start + 100 * k
        # RPDO3 = 0x6040 + 0x607A, taken at the next SYNC; TPDO3 answers every SYNC.
        send(client, RPDO3, [0x0F, 0x00] + list(target.to_bytes(4, "little", signed=True)))
        actual = position_on_sync(client)
        worst = max(worst, abs(target - actual))
        time.sleep(0.005)
    time.sleep(0.01)
    assert position_on_sync(client) == target
    assert worst <= 100, "lags more than one set-point: %d" % worst
    status = sdo_upload_expedited(client, NODE, 0x6041, 0)
    assert status & 0x1000, "bit 12: the drive follows the command value"
    assert status & 0x2000 == 0, "no following error"


def run_master(bus_server, *args):
    """`cia402 master` on the same bus, through socketcand: our master against our node, in real time."""
    url = "socketcand://127.0.0.1:%d/can0" % bus_server["port"]
    return subprocess.run([os.environ["CIA402_BIN"], "master", "--can", url, "--node", str(NODE)] + list(args),
                          capture_output=True, text=True, timeout=60)


def test_cia402_master_runs_the_modes_over_socketcand(bus_server):
    done = run_master(bus_server, "--json", "move", "12000", "--velocity", "900")
    assert done.returncode == 0, done.stderr
    events = [json.loads(line) for line in done.stdout.splitlines()]
    assert {"node": NODE, "event": "reached", "position": 12000} in events
    done = run_master(bus_server, "home", "--method", "37", "--offset", "-250")
    assert done.returncode == 0, done.stderr
    assert "homing attained, position -250" in done.stdout
    # csp: a ramp of 0x607A in RPDO3 before every 2 ms SYNC, 0x6064 back in TPDO3.
    done = run_master(bus_server, "--json", "csp-stream", "--to", "5000", "--velocity", "300", "--sync-us", "2000")
    assert done.returncode == 0, done.stderr
    events = [json.loads(line) for line in done.stdout.splitlines()]
    started = [e for e in events if e["event"] == "stream_started"]
    streamed = [e for e in events if e["event"] == "streamed"]
    assert len(started) == 1 and len(streamed) == 1 and streamed[0]["position"] == 5000
    # The stream starts where homing left the drive: 0x607A still held the move's 12000, and the
    # master pinned it to 0x6064 before the switch to csp, which follows 0x607A from its first cycle.
    assert started[0]["from"] == -250, started
    # 300 rpm x 10,000 increments a revolution = 100 increments a 2 ms SYNC: 5250 in 53, the last 50.
    assert streamed[0]["set_points"] == 53, streamed
    # The lag the master sees is reported but not bounded here: both processes run on wall time,
    # and when the bus server is held up (a loaded CI machine) the SYNCs queued meanwhile are all
    # answered in one pass, from one position, several set-points old for the last of them. The
    # drive's own check passed (bit 13 would have failed the run); the exact lag, none, is asserted
    # on the virtual bus in cli_test.
    assert streamed[0]["max_following_error"] >= 0
