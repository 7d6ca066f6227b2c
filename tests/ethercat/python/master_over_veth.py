"""Our EtherCAT master against our virtual drives over a veth pair, with every frame captured and
decoded by Wireshark's EtherCAT and CoE dissectors (tshark). For 1 and 16 drives: `cia402 ecat-slave`
on one end, `cia402 master --ecat` on the other bringing the line to OP and every drive through
enable, quick stop, an injected fault (0x2001 over the mailbox) and its reset. Then tshark reads the
capture: EtherCAT frames and CoE SDOs are there, and no frame is malformed or carries an expert
warning or error. Needs root (CI runs as root), iproute2 and tshark (scripts/install-deps.sh);
skips (exit 77) without root. Usage: master_over_veth.py CIA402_BINARY [KEEP_DIR]."""
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import veth_session  # noqa: E402  the veth pair with `cia402 ecat-slave` and tshark on it


def run_line(cia402, drives, workdir):
    tag = "%d%d" % (os.getpid() % 1000, drives)
    m, s = "c4em" + tag, "c4es" + tag
    pcap = os.path.join(workdir, "line-%d.pcapng" % drives)
    with veth_session.slave_line(cia402, m, s, drives, pcap):
        steps = ["state", "enable", "quick-stop", "enable", "sdo", "write", "0x2001", "0x2310", "wait", "50",
                 "sdo", "write", "0x2001", "0", "reset", "state"]
        master = subprocess.run([cia402, "master", "--ecat", m, "--json"] + steps, capture_output=True,
                                text=True, timeout=120)
        assert master.returncode == 0, master.stdout + master.stderr
        events = [json.loads(line) for line in master.stdout.splitlines()]
        time.sleep(0.5)  # the last answers into the capture
    check_session(events, drives)
    check_capture(pcap, drives)
    return events


def of(events, kind):
    return [e for e in events if e["event"] == kind]


def check_session(events, drives):
    assert of(events, "scan") == [{"event": "scan", "slaves": drives}], events[:2]
    slaves = of(events, "slave")
    assert [e["serial"] for e in slaves] == list(range(1, drives + 1)), slaves
    assert all(e["product_code"] == "0x00000402" for e in slaves), slaves
    assert all(e["station"] == "0x%04X" % (0x1001 + e["slave"]) for e in slaves), slaves
    op = of(events, "operational")
    assert len(op) == 1 and op[0]["working_counter"] == 3 * drives, op
    assert all(e["source"] == "CoE 0x1C12/0x1C13" for e in of(events, "mapping"))
    reached = of(events, "reached")
    enabled = [e for e in reached if e["state"] == "OPERATION_ENABLED"]
    assert len(enabled) == 2 * drives, reached  # enable, and enable again after the quick stop
    assert len(of(events, "quick_stop_done")) == drives
    faults = [e for e in of(events, "state") if e["state"] == "FAULT"]
    assert sorted(e["slave"] for e in faults) == list(range(drives)), faults
    assert all(e["error_code"] == "0x2310" for e in faults), faults
    emcy = [e["slave"] for e in of(events, "emcy") if e["error_code"] == "0x2310"]
    assert sorted(emcy) == list(range(drives)), of(events, "emcy")
    reset = [e for e in reached if e["state"] == "SWITCH_ON_DISABLED"]
    assert len(reset) == drives, reached
    final = of(events, "status")[-drives:]
    assert all(e["state"] == "SWITCH_ON_DISABLED" and e["error_code"] == "0x0000" for e in final), final
    assert of(events, "done")[0]["lost_frames"] == 0, of(events, "done")


def tshark(pcap, *args):
    r = subprocess.run(["tshark", "-r", pcap] + list(args), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return r.stdout


def check_capture(pcap, drives):
    frames = int(tshark(pcap, "-Y", "ecat", "-T", "fields", "-e", "frame.number").count("\n"))
    others = tshark(pcap, "-Y", "not ecat", "-T", "fields", "-e", "frame.number", "-e", "_ws.col.Protocol")
    assert frames > 100, frames
    assert others.strip() == "", "frames that are not EtherCAT on the line:\n" + others[:500]
    # The CoE dissector reads our SDOs (requests and responses) and the emergencies.
    sdo = int(tshark(pcap, "-Y", "ecat_mailbox.coe.sdoreq or ecat_mailbox.coe.sdores", "-T", "fields",
                     "-e", "frame.number").count("\n"))
    assert sdo > 0, "no CoE SDO decoded"
    emcy = tshark(pcap, "-Y", "ecat_mailbox.coe.type == 1", "-T", "fields", "-e", "frame.number")
    assert emcy.strip(), "no CoE emergency decoded"
    # No malformed frame, no expert warning or error (severity warn 0x600000, error 0x800000).
    bad = tshark(pcap, "-Y", "_ws.malformed or _ws.expert.severity >= 0x600000", "-T", "fields",
                 "-e", "frame.number", "-e", "_ws.col.Info")
    assert bad.strip() == "", "tshark flags frames:\n" + bad[:2000]
    print("line of %d: %d EtherCAT frames, %d CoE SDO frames, none malformed or flagged" % (drives, frames, sdo))


def run(cia402, workdir):
    for drives in (1, 16):
        run_line(cia402, drives, workdir)


def main():
    return veth_session.captured_main(run, "cia402-ecat-", missing_tool=1)


if __name__ == "__main__":
    sys.exit(main())
