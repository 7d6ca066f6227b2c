#!/usr/bin/env python3
"""The page's sign of life end to end, as CTest runs it:  sign_of_life_serve_test.py CIA402_BINARY [ecat]

For `cia402 serve --lease 500` (a virtual drive in the server's process) and for
`cia402 serve --can socketcand://... --lease 500` against `cia402 bus` (a free loopback port); with
`ecat`, for `cia402 serve --ecat IF --lease 500` against `cia402 ecat-slave` on the other end of a
veth pair (root and iproute2; skipped with exit 77 saying why otherwise): an
open event stream (the page) enables the drive through the HTTP API and sets it turning at 600 rpm;
for three lease times only the stream is open and the drive keeps turning; then the stream is closed
(the tab) and the drive must stand still, quick-stopped as its 0x6007 (1 by default) says, within
the bound docs/page.md states: the lease + 2 x 250 ms (the stream's probe that finds the page gone)
+ the quick-stop ramp (600 rpm at 0x6085 = 10000 rpm/s: 60 ms), here with 1 s more for a loaded
machine. While it waits the test reads GET /api/axes, which renews nothing. Processes are stopped by
their PIDs.
"""
import os
import socket
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve_can_test import Process, bus_and_serve, request, wait_state, settled_result  # noqa: E402
from commissioning_serve_test import over_ecat  # noqa: E402

LEASE_MS = 500
PROBE_MS = 250
TURNING_RPM = 600
RAMP_MS = TURNING_RPM * 1000 // 10000
MARGIN_MS = 1000


class EventStream:
    """GET /api/events on a socket of its own; the newest snapshot it brought; close() is the tab."""

    def __init__(self, base, axis=1):
        host, port = base.split('//')[1].rstrip('/').split(':')
        self.sock = socket.create_connection((host, int(port)), timeout=10)
        self.sock.sendall(f'GET /api/events?axis={axis} HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n'.encode())
        self.snapshots = 0
        self.closed = False
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        data = b''
        try:
            while not self.closed:
                chunk = self.sock.recv(65536)
                if not chunk:
                    return
                data += chunk
                self.snapshots += data.count(b'data: ')
                data = data[data.rfind(b'\n'):] if b'\n' in data else data
        except OSError:
            return

    def close(self):
        self.closed = True
        self.sock.shutdown(socket.SHUT_RDWR)
        self.sock.close()


def overview(base):
    """State and velocity of axis 1 from GET /api/axes (renews no lease)."""
    _, axes = request(base + 'api/axes')
    return axes[0]


def check(base, label):
    stream = EventStream(base)
    for name in ('shutdown', 'switch_on', 'enable_operation'):
        status, reply = request(base + 'api/command', {'command': name})
        assert status == 200, (label, name, status, reply)
        settled_result(base, reply['id'])
    wait_state(base, lambda s: s['state'] == 'OPERATION_ENABLED', 'OPERATION_ENABLED')
    status, reply = request(base + 'api/plant', {'target_velocity': TURNING_RPM})
    assert status == 200, (label, status, reply)
    wait_state(base, lambda s: s['velocity'] == TURNING_RPM, f'{TURNING_RPM} rpm')

    # Only the stream is open now, for three lease times: the drive keeps turning.
    end = time.monotonic() + 3 * LEASE_MS / 1000
    while time.monotonic() < end:
        o = overview(base)
        assert o['state'] == 'OPERATION_ENABLED' and o['velocity'] == TURNING_RPM, (label, o)
        time.sleep(0.05)
    assert stream.snapshots > 0, label
    print(f'ok - {label}: the open event stream kept the drive turning for {3 * LEASE_MS} ms')

    stream.close()
    closed_at = time.monotonic()
    bound = (LEASE_MS + 2 * PROBE_MS + RAMP_MS + MARGIN_MS) / 1000
    while True:
        o = overview(base)
        if o['velocity'] == 0 and o['state'] != 'OPERATION_ENABLED':
            break
        assert time.monotonic() - closed_at < bound, (label, 'still', o, 'after', bound, 's')
        time.sleep(0.02)
    took = time.monotonic() - closed_at
    assert took >= LEASE_MS / 1000 * 0.9, (label, 'stopped before the lease ran out', took)
    _, s = request(base + 'api/state')
    actions = [r['action'] for r in s['results']]
    assert any('SIGN OF LIFE LOST' in a and '0x6007 = 1' in a for a in actions), (label, actions)
    print(f'ok - {label}: tab closed, the drive stood still {took * 1000:.0f} ms later '
          f'(bound {bound * 1000:.0f} ms): {actions[0]}')


def main():
    if len(sys.argv) not in (2, 3) or (len(sys.argv) == 3 and sys.argv[2] != 'ecat'):
        print('usage: sign_of_life_serve_test.py CIA402_BINARY [ecat]', file=sys.stderr)
        return 2
    cia402 = sys.argv[1]
    if len(sys.argv) == 3:
        return over_ecat(cia402, check, ('--lease', str(LEASE_MS)))
    serve = Process([cia402, 'serve', '--port', '0', '--lease', str(LEASE_MS)])
    try:
        check(serve.wait_for(r'instrument page at (http://\S+/)').group(1), 'virtual drive')
        assert serve.stop() == 0, serve.output
    finally:
        serve.stop()

    with bus_and_serve(cia402, '1', ('--node', '1', '--lease', str(LEASE_MS))) as (bus, serve, base):
        wait_state(base, lambda s: s['remote']['status'] == 'running', 'set-up of node 1')
        check(base, 'serve --can')
        assert serve.stop() == 0, serve.output
        assert bus.stop() == 0, bus.output
    print('2 checks passed')
    return 0


if __name__ == '__main__':
    sys.exit(main())
