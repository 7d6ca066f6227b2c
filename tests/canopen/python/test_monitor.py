"""`cia402 monitor` on what python-can and `cia402 master` did on `cia402 bus`: from the bus's
candump log (--log) and live over socketcand, it decodes an SDO abort, an EMCY, heartbeats and
mapped TPDOs, the default mapping and the one `cia402 master` sets up over SDO."""
import json
import os
import signal
import subprocess
import time

import can
import pytest

BIN = os.environ.get("CIA402_BIN", "")


def start_bus(log=None):
    args = [BIN, "bus", "--listen", "127.0.0.1:0", "--nodes", "1-2"] + (["--log", log] if log else [])
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    assert "socketcand on 127.0.0.1:" in line, line + proc.stderr.read()
    return proc, int(line.split("127.0.0.1:")[1].split()[0])


def stop(proc):
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    return out, err


def session(port):
    """An SDO abort, a fault with its EMCY and heartbeats on node 1 (python-can, raw frames); node 2
    enabled by `cia402 master`, which maps TPDO1 = 0x6041 + 0x603F over SDO."""
    bus = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
    time.sleep(0.15)

    def sdo(data):
        bus.send(can.Message(arbitration_id=0x601, data=bytes(data), is_extended_id=False))
        end = time.monotonic() + 2
        while time.monotonic() < end:
            msg = bus.recv(timeout=0.1)
            if msg is not None and msg.arbitration_id == 0x581:
                return msg
        pytest.fail("no SDO answer")

    try:
        assert sdo([0x2F, 0x60, 0x60, 0x00, 0x02, 0, 0, 0]).data[0] == 0x80   # 0x6060 = 2: abort
        assert sdo([0x2B, 0x17, 0x10, 0x00, 50, 0, 0, 0]).data[0] == 0x60     # heartbeat 50 ms
        bus.send(can.Message(arbitration_id=0x000, data=[0x01, 1], is_extended_id=False))
        time.sleep(0.05)
        assert sdo([0x2B, 0x01, 0x20, 0x00, 0x10, 0x23, 0, 0]).data[0] == 0x60  # fault 0x2310
        time.sleep(0.15)
    finally:
        bus.shutdown()
    # `wait 300`: node 2 sends its heartbeat (0x1017 = 100 ms) as OPERATIONAL while the master runs;
    # when it ends, the master puts 0x1017 back to 0 and the heartbeats stop.
    master = subprocess.run([BIN, "master", "--can", "socketcand://127.0.0.1:%d/can0" % port, "--node", "2",
                             "enable", "wait", "300"], capture_output=True, text=True, timeout=30)
    assert master.returncode == 0, master.stdout + master.stderr
    time.sleep(0.05)


def check_decoded(records):
    by = lambda **kv: [r for r in records if all(r.get(k) == v for k, v in kv.items())]
    abort = by(kind="sdo", event="abort", node=1)
    assert abort and abort[0]["object"] == "0x6060:0" and abort[0]["code"] == "0x06090030", abort
    assert abort[0]["code_text"] == "invalid value for parameter"
    emcy = by(kind="emcy", node=1, event="error")
    assert emcy and emcy[0]["code"] == "0x2310" and emcy[0]["code_text"] == "continuous over-current", emcy
    assert by(kind="heartbeat", node=1, event="operational")
    assert by(kind="heartbeat", node=2, event="operational")  # `cia402 master` asks for 100 ms
    # Node 1's TPDO1 by the drive's predefined mapping: the status word, FAULT after the injection.
    tpdo1 = by(kind="pdo", node=1, event="TPDO1")
    assert tpdo1 and all([v["object"] for v in r["values"]] == ["0x6041:0"] for r in tpdo1), tpdo1
    assert "FAULT" in [r["values"][0].get("meaning") for r in tpdo1]
    # Node 2's TPDO1 as `cia402 master` remapped it over SDO: status word and error code.
    remapped = [r for r in by(kind="pdo", node=2, event="TPDO1") if len(r["values"]) == 2]
    assert remapped, by(kind="pdo", node=2)
    assert [v["object"] for v in remapped[-1]["values"]] == ["0x6041:0", "0x603F:0"]
    assert remapped[-1]["values"][0]["meaning"] == "OPERATION_ENABLED"
    assert not by(kind="unknown"), by(kind="unknown")


def test_monitor_decodes_the_bus_log(tmp_path):
    log = str(tmp_path / "bus.log")
    bus, port = start_bus(log)
    try:
        session(port)
    finally:
        stop(bus)
    decoded = subprocess.run([BIN, "monitor", "--log", log, "--json"], capture_output=True, text=True,
                             timeout=30)
    assert decoded.returncode == 0, decoded.stderr
    records = [json.loads(line) for line in decoded.stdout.splitlines()]
    assert len(records) == sum(1 for line in open(log) if line.strip())
    check_decoded(records)
    # The same as lines a person reads.
    text = subprocess.run([BIN, "monitor", "--log", log], capture_output=True, text=True, timeout=30).stdout
    for part in ("SDO abort 0x6060:0 0x06090030 invalid value for parameter",
                 "EMCY 0x2310 continuous over-current", "heartbeat OPERATIONAL",
                 "TPDO1 0x6041:0 = 0x", "(Statusword: OPERATION_ENABLED), 0x603F:0 = 0x0000 (Error code)"):
        assert part in text, part


def test_monitor_decodes_a_live_bus_over_socketcand():
    bus, port = start_bus()
    monitor = subprocess.Popen([BIN, "monitor", "socketcand://127.0.0.1:%d/can0" % port, "--json"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert "watching" in monitor.stderr.readline()
        time.sleep(0.15)  # the server sends a client its frames from 100 ms after it joined
        session(port)
        time.sleep(0.2)
        out, err = stop(monitor)
    finally:
        if monitor.poll() is None:
            monitor.kill()
        stop(bus)
    check_decoded([json.loads(line) for line in out.splitlines()])
