"""`cia402 bus --log FILE` read back by python-can's own reader of candump logs
(can.CanutilsLogReader): every frame the bus carried, the client's and the drives', in bus order and
with their content, while the bus still runs (the log is flushed as it goes)."""
import os
import signal
import subprocess
import time

import can
import pytest



@pytest.fixture
def logged_bus(tmp_path):
    log = str(tmp_path / "bus.log")
    proc = subprocess.Popen([os.environ["CIA402_BIN"], "bus", "--listen", "127.0.0.1:0", "--nodes", "1-2",
                             "--log", log], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    assert "socketcand on 127.0.0.1:" in line and "log " + log in line, line + proc.stderr.read()
    port = int(line.split("127.0.0.1:")[1].split()[0])
    yield {"port": port, "proc": proc, "log": log}
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err


def key(msg, extended=None):
    return (msg.arbitration_id, msg.is_extended_id if extended is None else extended,
            msg.is_remote_frame, bytes(msg.data) if not msg.is_remote_frame else b"")


def received_key(msg):
    # python-can 4.1's socketcand client marks every frame it receives extended; the drives and
    # this test send 11-bit frames only.
    return key(msg, extended=False)


class recording_client:
    """A python-can client that keeps what it sent and what it received, in order."""

    def __init__(self, port):
        self.bus = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
        self.sent, self.received = [], []
        time.sleep(0.15)  # the server starts sending frames 100 ms after rawmode

    def send(self, cob_id, data):
        msg = can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False)
        self.bus.send(msg)
        self.sent.append(key(msg))

    def wait(self, match, timeout=2.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            msg = self.bus.recv(timeout=max(0.0, end - time.monotonic()))
            if msg is not None:
                self.received.append(received_key(msg))
                if match(msg):
                    return msg
        return None

    def drain(self, quiet=0.3):
        while True:
            msg = self.bus.recv(timeout=quiet)
            if msg is None:
                return
            self.received.append(received_key(msg))


def sdo(client, node, data):
    client.send(0x600 + node, data)
    answer = client.wait(lambda m: m.arbitration_id == 0x580 + node)
    assert answer is not None, "no SDO answer"
    return answer


def test_the_log_reads_back_frame_for_frame_with_can_utils_log_reader(logged_bus):
    started = time.time()
    c = recording_client(logged_bus["port"])
    sdo(c, 1, [0x40, 0x00, 0x10, 0, 0, 0, 0, 0])                       # upload 0x1000
    first = sdo(c, 1, [0x40, 0x08, 0x10, 0, 0, 0, 0, 0])               # 0x1008, segmented
    assert first.data[0] == 0x41
    toggle = 0
    while True:
        seg = sdo(c, 1, [0x60 | (toggle << 4), 0, 0, 0, 0, 0, 0, 0])
        toggle ^= 1
        if seg.data[0] & 1:
            break
    assert sdo(c, 1, [0x2F, 0x60, 0x60, 0x00, 0x02, 0, 0, 0]).data[0] == 0x80  # abort: mode 2
    c.send(0x000, [0x01, 1])                                            # NMT start node 1
    assert c.wait(lambda m: m.arbitration_id == 0x181) is not None
    assert sdo(c, 1, [0x2B, 0x01, 0x20, 0x00, 0x10, 0x23, 0, 0]).data[0] == 0x60  # fault 0x2310
    emcy = c.wait(lambda m: m.arbitration_id == 0x081)
    assert emcy is not None and emcy.data[0:2] == b"\x10\x23"
    c.send(0x000, [0x81, 2])                                            # reset node 2: boot-up
    assert c.wait(lambda m: m.arbitration_id == 0x702) is not None
    c.send(0x000, [0x80, 0])              # every node PRE-OPERATIONAL: no more PDOs from here on
    c.drain()
    ended = time.time()

    # Read while the bus still runs: what the bus carried is in the file already.
    logged = list(can.CanutilsLogReader(logged_bus["log"]))
    assert logged_bus["proc"].poll() is None
    c.bus.shutdown()

    # Before the client's first frame the drives only booted (0x701, 0x702: 00).
    keys = [key(m) for m in logged]
    start = keys.index(c.sent[0])
    assert sorted(keys[:start]) == [(0x701, False, False, b"\x00"), (0x702, False, False, b"\x00")]
    # From there on the log is what the client sent merged, in bus order, with what it received.
    i = j = 0
    for k in keys[start:]:
        if i < len(c.sent) and k == c.sent[i]:
            i += 1
        elif j < len(c.received) and k == c.received[j]:
            j += 1
        else:
            pytest.fail("logged frame %r is neither the next sent %r nor the next received %r"
                        % (k, c.sent[i:i + 1], c.received[j:j + 1]))
    assert (i, j) == (len(c.sent), len(c.received))
    assert len(keys) == start + len(c.sent) + len(c.received)
    # The wall clock, in bus order, on every line; and the bus name as the interface.
    times = [m.timestamp for m in logged]
    assert times == sorted(times)
    assert started - 2 <= times[0] and times[-1] <= ended + 1
    assert {m.channel for m in logged} == {"can0"}
