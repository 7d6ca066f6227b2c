"""What a strict master sees on the wire (issue 34), decoded by Wireshark's EtherCAT and CoE
dissectors (tshark) from a capture of a veth pair: `cia402 ecat-slave` (2 drives) on one end, on
the other `cia402 master --ecat` and then a few raw frames written here (ETG.1000.4/.6 numbers
written out, not taken from our code). Checked from tshark's fields:
 - a refused SDO (download to read-only 0x1000, upload of absent 0x5FFF) comes back as a CoE SDO
   *request* (CoE service 2, ETG.1000.6 5.6.2.7) carrying an abort (command specifier 4) with the
   CiA 301 abort code (0x06010002, 0x06020000): SOEM and IgH take nothing else for an abort;
 - distributed clocks (ETG.1000.4 6.8, ETG.1020 DC set-up): the master latches the receive times
   (BWR 0x0900), writes offset 0x0920, delay 0x0928, SYNC0 cycle 0x09A0 and activation 0x0981 of
   each drive, and its cycle frames carry the reference clock's time (FRMW of 0x0910);
 - the AL error rule (ETG.1000.6 6.4.1.4): in INIT+ERR, PRE-OP requested without the acknowledge
   leaves AL status at 0x11; with the acknowledge it is taken (0x02);
 - the mailbox repeat (ETG.1000.4 SM, 0x080E bit 1 / 0x080F bit 1): after a toggled repeat request
   the repeat acknowledge follows and SM1 holds the same CoE reply again.
 - csp on SYNC0 (ETG.1020 §5.3): with DC set up, drive 0's 0x1C32:01 reads 0x02 (DC SYNC0
   synchronous) and a csp stream run by our master ends at its target, each set-point taken on SYNC0.
Needs root and tshark (scripts/install-deps.sh); skips (exit 77) without root or tshark.
Usage: strict_wire_over_veth.py CIA402_BINARY [KEEP_DIR]."""
import json
import os
import struct
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import veth_session  # noqa: E402  the raw-socket master and its frame writer

APRD, APWR, FPRD, FPWR, BRD, BWR, LRW, ARMW, FRMW = 1, 2, 4, 5, 7, 8, 12, 13, 14
LOGICAL = (10, 11, LRW)
STATION = 0x1001  # drive 0 as our master addresses it (0x1001 + position)
ABORT_READ_ONLY, ABORT_NO_OBJECT = 0x06010002, 0x06020000


def master(cia402, iface, steps):
    r = subprocess.run([cia402, "master", "--ecat", iface, "--json", "--timeout", "5000"] + steps,
                       capture_output=True, text=True, timeout=60)
    return r.returncode, [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")], r.stderr


def refused_sdos(cia402, iface):
    """Each refused step ends the master's run with the abort named: one run for each."""
    for steps, code in ((["sdo", "write", "0x1000", "0"], ABORT_READ_ONLY),
                        (["sdo", "read", "0x5FFF"], ABORT_NO_OBJECT)):
        rc, events, err = master(cia402, iface, ["--position", "0", "state"] + steps)
        failed = [e for e in events if e["event"] == "failed"]
        assert rc != 0 and failed, (rc, events[-3:], err)
        assert "0x%08x" % code in failed[0]["error"].lower(), failed


def csp_on_sync0(cia402, iface):
    """One run of our master: the synchronisation mode, then enable and a csp stream to 20000."""
    rc, events, err = master(cia402, iface, ["--position", "0", "sdo", "read", "0x1C32:1", "enable",
                                             "csp-stream", "--to", "20000", "--velocity", "300", "disable"])
    assert rc == 0, (rc, events[-3:], err)
    sync_mode = [e for e in events if e.get("object") == "0x1C32:1"]
    assert sync_mode and sync_mode[0]["value"] == 2, \
        "0x1C32:01 is %s, not 2 (DC SYNC0): the drive does not run its cycle on SYNC0" % sync_mode
    streamed = [e for e in events if e["event"] == "streamed"]
    assert streamed and streamed[0]["position"] == 20000, "the csp stream did not end at 20000: %s" % streamed
    return streamed[0]["set_points"]


def al_status(bus):
    data, wkc = bus.one(FPRD, STATION, 0x0130, [0] * 6)
    assert wkc == 1, "no AL status from the drive"
    return data[0], struct.unpack("<H", data[4:6])[0]


def al_control(bus, value, expect=None):
    """Requests a state; waits until AL status shows EXPECT (2 s at most), or 0.2 s when nothing may change."""
    bus.one(FPWR, STATION, 0x0120, [value, 0])
    deadline = time.monotonic() + (2.0 if expect is not None else 0.2)
    while True:
        time.sleep(0.01)
        status = al_status(bus)
        if status[0] == expect or time.monotonic() > deadline:
            return status


def al_error_and_repeat(iface):
    """Raw frames after the master is gone: the AL error rule, then a mailbox repeat."""
    bus = veth_session.master(iface)
    bus.one(APWR, 0, 0x0010, list(struct.pack("<H", STATION)))
    al_control(bus, 0x11, 0x01)  # INIT, acknowledging whatever the master left
    for n, (start, length, control) in enumerate(((0x1000, 128, 0x26), (0x1080, 128, 0x22))):
        bus.one(FPWR, STATION, 0x0800 + 8 * n, list(struct.pack("<HHBBBB", start, length, control, 0, 1, 0)))
    seen = [al_control(bus, 0x08, 0x11)]  # INIT -> OP is no transition: INIT+ERR
    seen.append(al_control(bus, 0x02))  # PRE-OP without the acknowledge: not honoured
    seen.append(al_control(bus, 0x12, 0x02))  # PRE-OP with the acknowledge: taken
    # An SDO upload of 0x1018:02 (product code); its reply read, then "lost": the repeat request brings it back.
    mbx = struct.pack("<HHBB", 10, 0, 0, 0x13) + struct.pack("<H", 0x2000) + bytes([0x40, 0x18, 0x10, 2, 0, 0, 0, 0])
    bus.one(FPWR, STATION, 0x1000, list(mbx + b"\0" * (128 - len(mbx))))
    time.sleep(0.05)
    first, wkc = bus.one(FPRD, STATION, 0x1080, [0] * 128)
    assert wkc == 1, "no reply in SM1"
    status_activate, _ = bus.one(FPRD, STATION, 0x080D, [0, 0])
    bus.one(FPWR, STATION, 0x080D, [status_activate[0], status_activate[1] ^ 0x02])
    deadline = time.monotonic() + 2
    while time.monotonic() < deadline:
        pdi, _ = bus.one(FPRD, STATION, 0x080F, [0])
        if (pdi[0] ^ (status_activate[1] ^ 0x02)) & 0x02 == 0:
            break
        time.sleep(0.01)
    again, wkc = bus.one(FPRD, STATION, 0x1080, [0] * 128)  # judged from the capture: empty if wkc is 0
    return seen, first[:16], again[:16] if wkc == 1 else None


FIELDS = ("frame.number", "ecat.cmd", "ecat.adp", "ecat.ado", "ecat.cnt", "ecat.data", "ecat.reg.alstatus",
          "ecat.reg.alstatuscode", "ecat_mailbox.coe.type", "ecat_mailbox.coe.sdoreq", "ecat_mailbox.coe.sdores",
          "ecat_mailbox.coe.abortcode", "ecat_mailbox.coe.sdoidx", "ecat_mailbox.coe.sdosub",
          "ecat_mailbox.coe.sdodata")
NUMERIC = set(FIELDS) - {"ecat.data"}


def decode(pcap):
    """One tshark pass (each costs a start-up): every EtherCAT frame as {field: [values, in order]}."""
    args = ["tshark", "-r", pcap, "-Y", "ecat", "-T", "fields", "-E", "occurrence=a"]
    for field in FIELDS:
        args += ["-e", field]
    r = subprocess.run(args, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    frames = []
    for line in r.stdout.splitlines():
        values = [v.split(",") if v else [] for v in line.split("\t")]
        frames.append({f: [int(x, 0) for x in v] if f in NUMERIC else v for f, v in zip(FIELDS, values)})
    return frames


def number(frame):
    return frame["frame.number"][0]


def answered(frame, cmd, ado):
    """A frame whose datagram CMD of ADO came back with working counter 1 (the test's own are single)."""
    return cmd in frame["ecat.cmd"] and ado in frame["ecat.ado"] and 1 in frame["ecat.cnt"]


def datagrams(frames):
    """Every datagram as (frame, command, adp, ado)."""
    out = []
    for f in frames:
        # A logical datagram (LRD, LWR, LRW) has a logical address, no ADP/ADO fields.
        physical = iter(zip(f["ecat.adp"], f["ecat.ado"]))
        for c in f["ecat.cmd"]:
            p, o = (-1, -1) if c in LOGICAL else next(physical)
            out.append((number(f), c, p, o))
    return out


def check_aborts(frames):
    # An abort under service 3 (SDO response): tshark shows command specifier 4 and no code.
    misfiled = [number(f) for f in frames if f["ecat_mailbox.coe.type"] == [3] and f["ecat_mailbox.coe.sdores"] == [4]
                and 1 in f["ecat.cnt"]]
    assert not misfiled, "aborts sent as CoE service 3 (SDO response), not 2, in frames %s" % misfiled
    # tshark 4.0 decodes an abort's code but not its index: the two refusals differ by code. Only the
    # slaves abort here: the master's requests never carry an abort code.
    got = {f["ecat_mailbox.coe.abortcode"][0]:
           (f["ecat_mailbox.coe.type"][0], (f["ecat_mailbox.coe.sdoreq"] or [-1])[0])
           for f in frames if f["ecat_mailbox.coe.abortcode"]}
    for code in (ABORT_READ_ONLY, ABORT_NO_OBJECT):
        assert code in got, "no abort 0x%08X decoded; aborts seen: %s" % (code, got)
        service, cmd = got[code]
        assert service == 2, "abort 0x%08X sent as CoE service %d, not 2 (SDO request)" % (code, service)
        assert cmd == 4, "abort 0x%08X with SDO request command specifier %d, not 4 (abort)" % (code, cmd)
    return len(got)


def check_distributed_clocks(dg):
    writes = {(a, p) for _, c, p, a in dg if c in (FPWR, APWR)}
    assert any(c == BWR and a == 0x0900 for _, c, _, a in dg), "no BWR of 0x0900 (receive time latch)"
    for register, name in ((0x0920, "offset"), (0x0928, "delay"), (0x0981, "activation"), (0x09A0, "SYNC0 cycle")):
        for station in (STATION, STATION + 1):
            assert (register, station) in writes, \
                "no write of 0x%04X (%s) to station 0x%04X" % (register, name, station)
    cycle_frames = {f for f, c, _, _ in dg if c == LRW}
    with_time = {f for f, c, _, a in dg if c in (FRMW, ARMW) and a == 0x0910}
    assert len(cycle_frames) > 10, "too few cycle frames"
    without = cycle_frames - with_time
    assert not without, "%d of %d cycle frames carry no FRMW/ARMW of 0x0910" % (len(without), len(cycle_frames))
    return len(cycle_frames)


def check_al_and_repeat(frames, seen, first, again):
    # The test's last three AL control writes (FPWR 0x0120) and, after each, the last AL status
    # answer (FPRD 0x0130, working counter 1) before the next write.
    writes = [number(f) for f in frames if answered(f, FPWR, 0x0120)][-3:]
    rows = [(number(f), f["ecat.reg.alstatus"][0], f["ecat.reg.alstatuscode"][0]) for f in frames
            if answered(f, FPRD, 0x0130) and f["ecat.reg.alstatuscode"]]
    wire = []
    for at, until in zip(writes, writes[1:] + [1 << 62]):
        answers = [(s, c) for n, s, c in rows if at < n < until]
        assert answers, "no AL status read after the AL control write in frame %d" % at
        wire.append(answers[-1])
    assert wire == seen, "the capture (%s) is not what the test read (%s)" % (wire, seen)
    assert wire[0] == (0x11, 0x0011), "INIT -> OP: AL status 0x%02X code 0x%04X, not INIT+ERR 0x0011" % wire[0]
    assert wire[1][0] == 0x11, "PRE-OP without the acknowledge was honoured: AL status 0x%02X, not 0x11" % wire[1][0]
    assert wire[2] == (0x02, 0), "PRE-OP with the acknowledge: AL status 0x%02X code 0x%04X, not 0x02" % wire[2]
    acks = [f["ecat.data"] for f in frames if answered(f, FPRD, 0x080F)]
    assert acks and int(acks[-1][0].replace(":", "")[0:2], 16) & 0x02, \
        "the repeat acknowledge (0x080F bit 1) never followed"
    request = [number(f) for f in frames if FPWR in f["ecat.cmd"] and 0x080D in f["ecat.ado"]]
    assert request, "no repeat request (FPWR 0x080D..0x080E) on the wire"
    replies = [(number(f), f["ecat_mailbox.coe.sdodata"][0]) for f in frames
               if f["ecat_mailbox.coe.sdoidx"] == [0x1018] and f["ecat_mailbox.coe.sdosub"] == [2]
               and f["ecat_mailbox.coe.type"] == [3] and 1 in f["ecat.cnt"] and f["ecat_mailbox.coe.sdodata"]]
    before = [d for n, d in replies if n < request[-1]]
    after = [d for n, d in replies if n > request[-1]]
    assert before and before[-1] == 0x402, "no 0x1018:02 reply before the repeat request: %s" % replies
    assert after == before[-1:], "after the repeat request SM1 did not hold the same reply again: %s" % replies
    assert first == again, (first.hex(), again.hex())


def run(cia402, workdir):
    tag = "%d" % (os.getpid() % 10000)
    m, s = "c4xm" + tag, "c4xs" + tag
    pcap = os.path.join(workdir, "strict.pcapng")
    with veth_session.slave_line(cia402, m, s, 2, pcap):
        refused_sdos(cia402, m)
        set_points = csp_on_sync0(cia402, m)
        seen, reply, again = al_error_and_repeat(m)
        time.sleep(0.3)  # the last answers into the capture
    frames = decode(pcap)
    aborts = check_aborts(frames)
    cycles = check_distributed_clocks(datagrams(frames))
    check_al_and_repeat(frames, seen, reply, again)
    print("on the wire: %d SDO aborts as CoE service 2, DC set up on 2 drives, %d cycle frames with FRMW 0x0910, "
          "PRE-OP refused until acknowledged, mailbox repeat answered, csp on SYNC0 (%d set-points)" % (aborts, cycles, set_points))


def main():
    return veth_session.captured_main(run, "cia402-strict-")


if __name__ == "__main__":
    sys.exit(main())
