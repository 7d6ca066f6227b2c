"""The two buses the master's end-to-end scripts run over: `cia402 bus` on a free loopback port, and
`cia402 ecat-slave` on one end of a veth pair (root). Each is a context manager that yields the
`cia402 master` options that reach node / slave 1, and ends what it started."""
import contextlib
import os
import shutil
import signal
import subprocess

SKIP = 77


class Skip(Exception):
    """The bus cannot be had here (not root, no iproute2): the script exits SKIP with the reason."""


@contextlib.contextmanager
def can_bus(cia402):
    bus = subprocess.Popen([cia402, "bus", "--listen", "127.0.0.1:0", "--nodes", "1"], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    try:
        first = bus.stdout.readline()
        assert "socketcand on 127.0.0.1:" in first, first + bus.stderr.read()
        port = int(first.split("127.0.0.1:")[1].split()[0])
        yield ["--can", "socketcand://127.0.0.1:%d/can0" % port, "--node", "1"]
    finally:
        bus.send_signal(signal.SIGTERM)
        bus.wait(timeout=10)


@contextlib.contextmanager
def ecat_line(cia402, prefix):
    if os.geteuid() != 0:
        raise Skip("a raw socket and a veth pair need root")
    if shutil.which("ip") is None:
        raise AssertionError("ip (iproute2) is missing (scripts/install-deps.sh installs it)")
    tag = "%d" % (os.getpid() % 10000)
    m, s = prefix + "m" + tag, prefix + "s" + tag
    subprocess.run(["ip", "link", "add", m, "type", "veth", "peer", "name", s], check=True)
    slave = None
    try:
        for name in (m, s):
            subprocess.run(["ip", "link", "set", name, "up"], check=True)
        slave = subprocess.Popen([cia402, "ecat-slave", "--iface", s, "--nodes", "1"], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        first = slave.stdout.readline()
        assert "1 drive(s) on %s" % s in first, first + slave.stderr.read()
        yield ["--ecat", m, "--position", "0"]
    finally:
        if slave is not None:
            slave.send_signal(signal.SIGTERM)
            slave.wait(timeout=10)
        subprocess.run(["ip", "link", "del", m], capture_output=True)
