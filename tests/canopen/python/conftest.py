"""Fixtures: a `cia402 bus` on a free loopback port, and python-can clients joining it through
python-can's own socketcand interface (no code of ours on the client side)."""
import os
import signal
import subprocess
import time

import can
import pytest


@pytest.fixture
def bus_server():
    binary = os.environ["CIA402_BIN"]
    proc = subprocess.Popen([binary, "bus", "--listen", "127.0.0.1:0", "--nodes", "1-2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    assert "socketcand on 127.0.0.1:" in line, line + proc.stderr.read()
    port = int(line.split("127.0.0.1:")[1].split()[0])
    yield {"port": port, "proc": proc}
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert "stopped" in out


@pytest.fixture
def client(bus_server):
    bus = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=bus_server["port"])
    time.sleep(0.15)  # the server starts sending frames 100 ms after rawmode
    yield bus
    bus.shutdown()
