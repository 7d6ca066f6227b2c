"""`cia402 ecat-slave` on one end of a veth pair, a raw-socket master written here on the other:
the frames a master sends at start-up (ETG.1000.4/.6 numbers written out here, not taken from our
code) travel through the kernel and come back answered. Needs root (CI runs as root) and iproute2;
skips (exit 77) saying why otherwise. Usage: veth_session.py CIA402_BINARY. Also the line the
tshark tests (master_over_veth.py, strict_wire_over_veth.py) run on: slave_line()."""
import contextlib
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time

SKIP = 77
ETHERTYPE = 0x88A4
MASTER_MAC = bytes([0x02, 0, 0, 0, 0, 0x01])


def datagram(cmd, adp, ado, data, index=0, more=False):
    length = len(data) | (0x8000 if more else 0)
    return struct.pack("<BBHHHH", cmd, index, adp & 0xFFFF, ado, length, 0) + bytes(data) + b"\0\0"


def frame(datagrams):
    body = b"".join(datagrams)
    f = b"\xff" * 6 + MASTER_MAC + struct.pack(">H", ETHERTYPE) + struct.pack("<H", len(body) | 0x1000) + body
    return f + b"\0" * max(0, 60 - len(f))


class master:
    def __init__(self, iface):
        self.sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETHERTYPE))
        self.sock.bind((iface, ETHERTYPE))
        self.sock.settimeout(1.0)

    def one(self, cmd, adp, ado, data):
        """One datagram out and back: (data, working counter)."""
        self.sock.send(frame([datagram(cmd, adp, ado, data)]))
        end = time.monotonic() + 2
        while time.monotonic() < end:
            raw, address = self.sock.recvfrom(2048)
            if address[2] == socket.PACKET_OUTGOING or raw[6] & 0x02 == 0:
                continue  # our own frame going out, not the answer
            n = len(data)
            payload = raw[16 + 10:16 + 10 + n]
            wkc = struct.unpack("<H", raw[16 + 10 + n:16 + 12 + n])[0]
            return payload, wkc
        raise AssertionError("no answer from the slaves")


def start_capture(iface, pcap):
    """tshark capturing the EtherCAT frames on IFACE into PCAP, once it says it captures."""
    capture = subprocess.Popen(["tshark", "-i", iface, "-f", "ether proto 0x88a4", "-w", pcap, "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:  # tshark says "Capturing on" once it captures
        line = capture.stderr.readline()
        if "Capturing on" in line:
            return capture
        assert line or capture.poll() is None, "tshark did not start"
    raise AssertionError("tshark did not start capturing within 30 s")


@contextlib.contextmanager
def slave_line(cia402, m, s, drives, pcap):
    """A veth pair M-S: `cia402 ecat-slave` with DRIVES drives on S, and tshark capturing M into PCAP
    while the block runs; the pair is gone after it."""
    subprocess.run(["ip", "link", "add", m, "type", "veth", "peer", "name", s], check=True)
    slave = capture = None
    try:
        for name in (m, s):
            subprocess.run(["ip", "link", "set", name, "up"], check=True)
        slave = subprocess.Popen([cia402, "ecat-slave", "--iface", s, "--nodes", str(drives)],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        first = slave.stdout.readline()
        assert "%d drive(s) on %s" % (drives, s) in first, first + slave.stderr.read()
        capture = start_capture(m, pcap)
        yield
    finally:
        if capture is not None:
            capture.send_signal(signal.SIGINT)
            capture.wait(timeout=30)
        if slave is not None:
            slave.send_signal(signal.SIGTERM)
            slave.wait(timeout=10)
        subprocess.run(["ip", "link", "del", m], capture_output=True)


def captured_main(run, prefix, missing_tool=SKIP):
    """The tshark tests' main, SCRIPT CIA402_BINARY [KEEP_DIR]: run(cia402, workdir) in KEEP_DIR, or
    in a temporary folder (PREFIX...) removed after. Without root: SKIP; without ip or tshark:
    `missing_tool` (SKIP, or 1 for a test that must not pass by skipping)."""
    if os.geteuid() != 0:
        print("SKIPPED: a raw socket and a veth pair need root")
        return SKIP
    for tool in ("ip", "tshark"):
        if shutil.which(tool) is None:
            print("%s: %s is missing (scripts/install-deps.sh installs it)"
                  % ("SKIPPED" if missing_tool == SKIP else "FAILED", tool))
            return missing_tool
    keep = sys.argv[2] if len(sys.argv) > 2 else None
    workdir = keep or tempfile.mkdtemp(prefix=prefix)
    try:
        run(sys.argv[1], workdir)
    finally:
        if keep is None:
            shutil.rmtree(workdir, ignore_errors=True)
    return 0


def main():
    if os.geteuid() != 0:
        print("SKIPPED: a raw socket and a veth pair need root")
        return SKIP
    if subprocess.run(["ip", "-V"], capture_output=True).returncode != 0:
        print("SKIPPED: iproute2 (ip) is missing")
        return SKIP
    m, s = "c4m%d" % (os.getpid() % 10000), "c4s%d" % (os.getpid() % 10000)
    if subprocess.run(["ip", "link", "add", m, "type", "veth", "peer", "name", s]).returncode != 0:
        print("SKIPPED: cannot create a veth pair here")
        return SKIP
    slave = None
    try:
        for name in (m, s):
            subprocess.run(["ip", "link", "set", name, "up"], check=True)
        slave = subprocess.Popen([sys.argv[1], "ecat-slave", "--iface", s, "--nodes", "2"],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = slave.stdout.readline()
        assert "2 drive(s) on " + s in line, line + slave.stderr.read()
        bus = master(m)
        time.sleep(0.2)
        # BRD of the type register: both slaves answer (working counter 2).
        data, wkc = bus.one(7, 0, 0x0000, [0, 0])
        assert wkc == 2, wkc
        # APWR station addresses by position (auto-increment: 0, then -1).
        for position, station in ((0, 0x1001), (1, 0x1002)):
            _, wkc = bus.one(2, -position, 0x0010, list(struct.pack("<H", station)))
            assert wkc == 1, (position, wkc)
        status, wkc = bus.one(4, 0x1002, 0x0130, [0, 0])
        assert wkc == 1 and status[0] == 1, (status, wkc)  # INIT
        # SII word 0x0A..0x0B: the product code, through the EEPROM interface.
        bus.one(5, 0x1001, 0x0504, list(struct.pack("<I", 0x0A)))
        bus.one(5, 0x1001, 0x0502, [0x00, 0x01])
        eeprom, wkc = bus.one(4, 0x1001, 0x0508, [0] * 8)
        assert wkc == 1 and struct.unpack("<I", eeprom[0:4])[0] == 0x402, eeprom
        # Mailbox sync managers as the SII says, then PRE-OP.
        for n, (start, length, control) in enumerate(((0x1000, 128, 0x26), (0x1080, 128, 0x22))):
            bus.one(5, 0x1001, 0x0800 + 8 * n, list(struct.pack("<HHBBBB", start, length, control, 0, 1, 0)))
        bus.one(5, 0x1001, 0x0120, [0x02, 0x00])
        time.sleep(0.05)
        status, _ = bus.one(4, 0x1001, 0x0130, [0, 0])
        assert status[0] == 2, status  # PRE-OP
        # CoE: an expedited SDO upload of 0x1018 sub 2 (product code) through the mailbox.
        mbx = struct.pack("<HHBB", 10, 0, 0, 0x13) + struct.pack("<H", 0x2000) + bytes([0x40, 0x18, 0x10, 2, 0, 0, 0, 0])
        _, wkc = bus.one(5, 0x1001, 0x1000, list(mbx + b"\0" * (128 - len(mbx))))
        assert wkc == 1, wkc
        time.sleep(0.05)
        reply, wkc = bus.one(4, 0x1001, 0x1080, [0] * 128)
        assert wkc == 1, "no reply in the send mailbox"
        assert reply[5] & 0x0F == 3 and reply[7] >> 4 == 3 and reply[8] == 0x43, reply[:16]
        assert struct.unpack("<I", reply[12:16])[0] == 0x402, reply[:16]
        # The DC system time (0x0910) as a master reads it between cycles: the host's clock to the
        # nanosecond, so successive reads a round trip apart differ (the drives' 1 ms steps would
        # give equal reads and jumps of 1 ms), and across the reads it kept the host's time.
        times, stamps = [], []
        for _ in range(400):
            data, wkc = bus.one(4, 0x1001, 0x0910, [0] * 8)
            assert wkc == 1, wkc
            times.append(struct.unpack("<Q", data)[0])
            stamps.append(time.monotonic_ns())
        steps = [b - a for a, b in zip(times, times[1:])]
        assert all(d >= 0 for d in steps), "the system time went back"
        moved = sum(1 for d in steps if d > 0)
        assert moved >= 0.9 * len(steps), "only %d of %d reads saw the time move" % (moved, len(steps))
        fine = sorted(steps)[len(steps) // 2]
        assert fine < 1_000_000 and fine % 1_000_000 != 0, "the median step is %d ns" % fine
        host = stamps[-1] - stamps[0]
        assert abs((times[-1] - times[0]) - host) < 0.05 * host + 200_000, (times[-1] - times[0], host)
        slave.send_signal(signal.SIGTERM)
        out, err = slave.communicate(timeout=10)
        assert slave.returncode == 0, err
        assert "stopped after" in out, out
        print("ecat-slave over veth: 2 slaves found, addressed, SII read, PRE-OP, CoE SDO upload answered, "
              "0x0910 read at a median step of %d ns" % fine)
        return 0
    finally:
        if slave is not None and slave.poll() is None:
            slave.kill()
        subprocess.run(["ip", "link", "del", m], capture_output=True)


if __name__ == "__main__":
    sys.exit(main())
