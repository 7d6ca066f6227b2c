#!/usr/bin/env python3
"""One-click Enable, the jog with its dead-man, and Stop over a bus, as CTest runs it:
commissioning_serve_test.py CIA402_BINARY can|ecat

`can`: `cia402 bus --listen 127.0.0.1:0 --nodes 1` and `cia402 serve --can socketcand://...`.
`ecat`: `cia402 ecat-slave` on one end of a veth pair and `cia402 serve --ecat` on the other (needs
root and iproute2; skips with exit 77 saying why otherwise).

Through the page's HTTP API (POST /api/enable, /api/jog, /api/stop): Enable walks the drive to
OPERATION ENABLED; a jog at 300 rpm renewed every 100 ms turns the drive at 300 rpm in profile
velocity (0x6060 = 3); a release (velocity 0) brings 0x60FF to 0 and the shaft to rest, the drive
still enabled; a jog whose keep-alives stop has 0x60FF = 0 within its time-to-live (300 ms) plus a
margin for the bus and a loaded machine; Stop ends in SWITCH ON DISABLED. Over EtherCAT the parameter list comes from the drive's CoE SDO
information (0x1C32, 0x1C12, 0x1A00 listed and read). Processes are stopped by their PIDs.
"""
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_can_test import Process, bus_and_serve, request, wait_state, settled_result  # noqa: E402

SKIP = 77
JOG_RPM = 300
TTL_MS = 300
MARGIN_MS = 700  # the bus's cycle, the snapshots' 40 ms, a loaded machine


def post(base, path, body):
    status, reply = request(base + path, body)
    assert status == 200, (path, body, status, reply)
    return reply


def check(base, label):
    r = post(base, 'api/enable', {})
    wait_state(base, lambda s: s['state'] == 'OPERATION_ENABLED', 'OPERATION_ENABLED')
    result = settled_result(base, r['id'])
    assert result['outcome'] == 'done', (label, result)
    print(f'ok - {label}: Enable: {result["text"]}')

    # Held: a keep-alive every 100 ms.
    end = time.monotonic() + 3
    while time.monotonic() < end:
        post(base, 'api/jog', {'velocity': JOG_RPM, 'ttl_ms': TTL_MS})
        time.sleep(0.1)
    _, s = request(base + 'api/state')
    assert s['velocity'] == JOG_RPM and s['mode'] == 3, (label, s['velocity'], s['mode'])
    print(f'ok - {label}: jog held: {s["velocity"]} rpm in profile velocity')

    # Released: 0x60FF = 0, the shaft comes to rest, the drive stays enabled.
    post(base, 'api/jog', {'velocity': 0})
    s = wait_state(base, lambda s: s['velocity'] == 0, 'standstill after the release', timeout=5)
    assert s['state'] == 'OPERATION_ENABLED', (label, s['state'])
    assert s['objects'].get('0x60FF', 0) == 0 or s['target_velocity'] == 0, (label, s['target_velocity'])
    print(f'ok - {label}: jog released: at rest, still OPERATION_ENABLED')

    # The dead-man: the keep-alives stop, 0x60FF goes to 0 within the time-to-live (plus the margin).
    post(base, 'api/jog', {'velocity': JOG_RPM, 'ttl_ms': TTL_MS})
    wait_state(base, lambda s: s['target_velocity'] == JOG_RPM, 'the jog turning', timeout=5)
    last = time.monotonic()
    post(base, 'api/jog', {'velocity': JOG_RPM, 'ttl_ms': TTL_MS})
    wait_state(base, lambda s: s['target_velocity'] == 0, '0x60FF = 0 after the dead-man', timeout=5)
    took = time.monotonic() - last
    assert took <= (TTL_MS + MARGIN_MS) / 1000, (label, 'dead-man took', took)
    print(f'ok - {label}: no keep-alive: 0x60FF = 0 after {took * 1000:.0f} ms (time-to-live {TTL_MS} ms)')

    r = post(base, 'api/stop', {})
    wait_state(base, lambda s: s['state'] == 'SWITCH_ON_DISABLED', 'SWITCH_ON_DISABLED after Stop')
    result = settled_result(base, r['id'])
    assert result['outcome'] == 'done', (label, result)
    print(f'ok - {label}: Stop: {result["text"]}')


def check_ecat_parameters(base, label):
    """The parameter list from the drive's CoE SDO information: the EtherCAT objects beyond the CiA
    402 table (sync manager parameters, PDO assignment) are listed with their names and read."""
    status, reply = request(base + 'api/parameters')
    assert status == 200, (label, status, reply)
    entries = {(e['index'].upper(), e['sub']): e for e in reply['entries']}
    for key, name in ((('0X1C32', 1), 'Sync mode'), (('0X1C12', 1), None), (('0X1A00', 1), None)):
        assert key in entries, (label, key, 'not listed')
        if name is not None:
            assert entries[key]['name'] == name, (label, key, entries[key]['name'])
        assert 'value' in entries[key], (label, key, entries[key])
    print(f'ok - {label}: parameter list from SDO information: {len(entries)} entries, 0x1C32, 0x1C12, 0x1A00 among them')
    check(base, label)


def over_can(cia402):
    with bus_and_serve(cia402, '1', ('--node', '1')) as (_, serve, base):
        wait_state(base, lambda s: s['remote']['status'] == 'running', 'set-up of node 1')
        check(base, 'serve --can')
        assert serve.stop() == 0, serve.output
    return 0


def veth_pair():
    """A veth pair (master end, slave end), or why there is none."""
    if os.geteuid() != 0:
        return None, 'a raw socket and a veth pair need root'
    if subprocess.run(['ip', '-V'], capture_output=True).returncode != 0:
        return None, 'iproute2 (ip) is missing'
    m, s = 'c4pm%d' % (os.getpid() % 10000), 'c4ps%d' % (os.getpid() % 10000)
    if subprocess.run(['ip', 'link', 'add', m, 'type', 'veth', 'peer', 'name', s]).returncode != 0:
        return None, 'cannot create a veth pair here'
    for name in (m, s):
        subprocess.run(['ip', 'link', 'set', name, 'up'], check=True)
    return (m, s), ''


def over_ecat(cia402, run=check, serve_args=()):
    """`run(base, label)` against `cia402 serve --ecat` on a veth pair; 77 where there is none."""
    pair, why = veth_pair()
    if pair is None:
        print(f'SKIPPED: {why}')
        return SKIP
    m, s = pair
    slave = serve = None
    try:
        slave = Process([cia402, 'ecat-slave', '--iface', s, '--nodes', '1'])
        slave.wait_for(r'drive\(s\) on ' + s)
        serve = Process([cia402, 'serve', '--ecat', m, '--position', '0', '--port', '0', *serve_args])
        base = serve.wait_for(r'instrument page at (http://\S+/)', timeout=30).group(1)
        wait_state(base, lambda st: st['remote']['status'] == 'running', 'slave 0 in OP')
        run(base, 'serve --ecat')
        assert serve.stop() == 0, serve.output
        serve = None
        return 0
    finally:
        for p in (serve, slave):
            if p is not None:
                p.stop()
        subprocess.run(['ip', 'link', 'del', m], capture_output=True)


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in ('can', 'ecat'):
        print('usage: commissioning_serve_test.py CIA402_BINARY can|ecat', file=sys.stderr)
        return 2
    return over_can(sys.argv[1]) if sys.argv[2] == 'can' else over_ecat(sys.argv[1], check_ecat_parameters)


if __name__ == '__main__':
    sys.exit(main())
