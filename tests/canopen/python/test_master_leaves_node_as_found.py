"""`cia402 master` leaves a node as it found it. What python-canopen's BaseNode402 reads when it
sets a node up (PdoBase.read(): each PDO's communication and mapping parameters) and the error
control objects, read here over SDO with python-can, are the same after a run as before: after the
issue's done-when command, after a run ended by SIGINT, and on a node another tool had configured
first. Then the node works the way such a tool expects: TPDO1 (event-driven again) brings each new
status word without a SYNC. Object numbers are CiA 301's, written out here."""
import json
import os
import signal
import subprocess
import time

from test_bus_python_can import NODE, send, wait_for, sdo_download

RPDO1, TPDO1 = 0x200 + NODE, 0x180 + NODE


def sdo_read(bus, index, sub):
    """The value of an expedited upload, or ("abort", code)."""
    while bus.recv(timeout=0) is not None:
        pass
    send(bus, 0x600 + NODE, [0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])
    msg = wait_for(bus, lambda m: m.arbitration_id == 0x580 + NODE and m.data[1] | (m.data[2] << 8) == index)
    assert msg is not None, "no SDO answer for 0x%04X:%d" % (index, sub)
    if msg.data[0] == 0x80:
        return ("abort", int.from_bytes(msg.data[4:8], "little"))
    size = 4 - ((msg.data[0] >> 2) & 3) if msg.data[0] & 0x01 else 4
    return int.from_bytes(msg.data[4:4 + size], "little")


def configuration(bus):
    """0x1400..0x1403 and 0x1800..0x1803 (subs 1, 2, 3, 5), their mappings (subs 0..8), 0x1016
    (subs 1..4) and 0x1017."""
    found = {}
    for comm in list(range(0x1400, 0x1404)) + list(range(0x1800, 0x1804)):
        for sub in (1, 2, 3, 5):
            found[(comm, sub)] = sdo_read(bus, comm, sub)
        for sub in range(0, 9):
            found[(comm + 0x200, sub)] = sdo_read(bus, comm + 0x200, sub)
    for sub in range(1, 5):
        found[(0x1016, sub)] = sdo_read(bus, 0x1016, sub)
    found[(0x1017, 0)] = sdo_read(bus, 0x1017, 0)
    return found


def master(bus_server, *args):
    url = "socketcand://127.0.0.1:%d/can0" % bus_server["port"]
    return [os.environ["CIA402_BIN"], "master", "--can", url, "--node", str(NODE)] + list(args)


def differences(before, after):
    return {k: (before[k], after[k]) for k in before if before[k] != after[k]}


def test_done_when_command_leaves_the_pdo_configuration_as_it_was(bus_server, client):
    before = configuration(client)
    done = subprocess.run(master(bus_server, "--json", "enable", "mode", "pp", "move", "20000", "mode", "pv",
                                 "velocity", "300", "wait", "500", "home", "37", "sdo", "write", "0x1017", "100",
                                 "sdo", "read", "0x1017", "sdo", "read", "0x1008", "quick-stop", "reset", "disable"),
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert differences(before, configuration(client)) == {}


def test_a_run_ended_by_sigint_leaves_it_as_it_was_and_the_drive_stopped(bus_server, client):
    before = configuration(client)
    proc = subprocess.Popen(master(bus_server, "--json", "--hold", "enable", "velocity", "600"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        for line in proc.stdout:
            e = json.loads(line)
            if e["event"] == "reached" and "velocity_rpm" in e:
                break
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, out + err  # every step was done; --hold ends on a signal
    assert differences(before, configuration(client)) == {}
    # Stopped as 0x6007 says, not left turning: 0x606C reads 0 once the stop has run.
    end = time.monotonic() + 10
    while sdo_read(client, 0x606C, 0) != 0 and time.monotonic() < end:
        time.sleep(0.05)
    assert sdo_read(client, 0x606C, 0) == 0


def test_a_node_another_tool_configured_gets_that_configuration_back(bus_server, client):
    # TPDO1 synchronous every 2nd SYNC and mapped to 0x6041 alone: another tool's choice.
    assert sdo_download(client, NODE, 0x1800, 1, 0x80000000 | (0x180 + NODE), 4).data[0] == 0x60
    assert sdo_download(client, NODE, 0x1800, 2, 2, 1).data[0] == 0x60
    assert sdo_download(client, NODE, 0x1800, 1, 0x180 + NODE, 4).data[0] == 0x60
    assert sdo_download(client, NODE, 0x1017, 0, 250, 2).data[0] == 0x60
    before = configuration(client)
    done = subprocess.run(master(bus_server, "enable", "disable"), capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stdout + done.stderr
    assert differences(before, configuration(client)) == {}


def test_after_the_master_a_status_word_arrives_in_tpdo1_without_sync(bus_server, client):
    done = subprocess.run(master(bus_server, "enable", "disable"), capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stdout + done.stderr
    assert sdo_read(client, 0x1800, 2) == 255  # event-driven, as the node's default
    send(client, RPDO1, [0x06, 0x00])  # Shutdown: the state changes, TPDO1 says so at once
    msg = wait_for(client, lambda m: m.arbitration_id == TPDO1 and (m.data[0] & 0x6F) == 0x21, timeout=2)
    assert msg is not None, "no TPDO1 with READY TO SWITCH ON"
