#!/usr/bin/env python3
"""`cia402 serve --can` end to end, as CTest runs it:  serve_can_test.py CIA402_BINARY

Starts `cia402 bus --listen 127.0.0.1:0 --nodes 1-2` (a free loopback port, printed by the bus), then
`cia402 serve --can socketcand://127.0.0.1:PORT/can0 --node 1 --node 2 --port 0` (two axes), and
drives the page's HTTP
API with the standard library only: the node is set up, Shutdown / Switch on / Enable operation
reach OPERATION ENABLED by the inferred transitions 2, 3, 4 (the standard's numbers, seed
002_522d2c0bb8f5a5f8.txt); a fault through the bus node's 0x2001 gives FAULT, a reset after the
cause is gone SWITCH ON DISABLED by 15; STO is refused with the reason; node 2 is an axis of its
own; the recorder holds the inferred transitions; when the bus goes away the
page says so and the server keeps answering. Both processes are stopped by their PIDs.
"""
import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request


class Process:
    """A child whose output is collected by a thread, so a full pipe never blocks it."""

    def __init__(self, args):
        self.args = args
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.output = ''
        self.lock = threading.Lock()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            with self.lock:
                self.output += line

    def wait_for(self, pattern, timeout=15):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                m = re.search(pattern, self.output)
            if m:
                return m
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise AssertionError(f'{self.args[1]}: no {pattern!r} in its output:\n{self.output}')

    def stop(self):
        """SIGTERM by PID; returns the exit status."""
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.kill(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.reader.join(timeout=2)
        return self.proc.returncode


@contextlib.contextmanager
def bus_and_serve(cia402, nodes, serve_args):
    """`cia402 bus --listen 127.0.0.1:0 --nodes NODES` and `cia402 serve --can` on the port it printed,
    with SERVE_ARGS: (bus, serve, the page's base URL) while the block runs; both stopped after."""
    bus = serve = None
    try:
        bus = Process([cia402, 'bus', '--listen', '127.0.0.1:0', '--nodes', nodes])
        port = int(bus.wait_for(r'socketcand on 127\.0\.0\.1:(\d+)').group(1))
        serve = Process([cia402, 'serve', '--can', f'socketcand://127.0.0.1:{port}/can0', *serve_args, '--port', '0'])
        yield bus, serve, serve.wait_for(r'instrument page at (http://\S+/)').group(1)
    finally:
        for p in (serve, bus):
            if p is not None:
                p.stop()


def request(url, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method='GET' if body is None else 'POST')
    if body is not None:
        req.add_header('Content-Type', 'application/json')
    try:
        with urllib.request.urlopen(req, timeout=15) as res:
            return res.status, json.loads(res.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def wait_state(base, predicate, what, timeout=10):
    deadline = time.monotonic() + timeout
    snapshot = None
    while time.monotonic() < deadline:
        _, snapshot = request(base + 'api/state')
        if predicate(snapshot):
            return snapshot
        time.sleep(0.05)
    raise AssertionError(f'{what} not reached in {timeout} s; last snapshot:\n'
                         f'{json.dumps(snapshot, indent=1)}')


def settled_result(base, action_id, timeout=10):
    """The result of one action once it is no longer pending."""
    def done(s):
        return any(r['id'] == action_id and r['outcome'] != 'pending' for r in s['results'])
    s = wait_state(base, done, f'result {action_id}', timeout)
    return next(r for r in s['results'] if r['id'] == action_id)


def command(base, name, expected_state, expected_transitions):
    status, reply = request(base + 'api/command', {'command': name})
    assert status == 200, (name, status, reply)
    result = settled_result(base, reply['id'])
    assert result['transitions'] == expected_transitions, (name, result)
    s = wait_state(base, lambda s: s['state'] == expected_state, expected_state)
    return s


def main():
    if len(sys.argv) != 2:
        print('usage: serve_can_test.py CIA402_BINARY', file=sys.stderr)
        return 2
    cia402 = sys.argv[1]
    checks = 0
    with bus_and_serve(cia402, '1-2', ('--node', '1', '--node', '2')) as (bus, serve, base):
        s = wait_state(base, lambda s: s['remote']['status'] == 'running', 'set-up of node 1')
        assert s['state'] == 'SWITCH_ON_DISABLED', s['state']
        assert s['remote']['device_name'] == 'cia402 virtual drive', s['remote']
        _, info = request(base + 'api/info')
        assert info['backend'] == 'remote' and info['remote']['node'] == 1, info.get('remote')
        checks += 1
        print('ok 1 - node 1 set up over socketcand, SWITCH_ON_DISABLED')

        command(base, 'shutdown', 'READY_TO_SWITCH_ON', [2])
        command(base, 'switch_on', 'SWITCHED_ON', [3])
        s = command(base, 'enable_operation', 'OPERATION_ENABLED', [4])
        assert s['last_transition']['number'] == 4 and s['last_transition']['inferred'], s
        assert s['control_word'] == '0x000F', s['control_word']
        checks += 1
        print('ok 2 - shutdown, switch on, enable operation: OPERATION_ENABLED by T2, T3, T4')

        status, reply = request(base + 'api/plant', {'sto': True})
        assert status == 409 and 'not available on a remote drive' in reply['error'], reply
        status, reply = request(base + 'api/object', {'index': '0x605A', 'value': 12})
        assert status == 422 and reply.get('abort') == '0x06090030', (status, reply)
        checks += 1
        print('ok 3 - STO refused with the reason; a refused option write carries its abort code')

        status, reply = request(base + 'api/plant', {'fault': True, 'fault_code': '0x2310'})
        assert status == 200, (status, reply)
        result = settled_result(base, reply['id'])
        assert result['transitions'] == [13, 14], result
        s = wait_state(base, lambda s: s['state'] == 'FAULT', 'FAULT')
        assert s['error_code'] == '0x2310', s['error_code']
        assert s['error_text'] == 'continuous over-current', s['error_text']
        status, reply = request(base + 'api/plant', {'fault': False})
        assert status == 200, (status, reply)
        settled_result(base, reply['id'])
        s = command(base, 'fault_reset', 'SWITCH_ON_DISABLED', [15])
        assert s['last_transition']['number'] == 15, s['last_transition']
        checks += 1
        print('ok 4 - fault through 0x2001: FAULT by T13, T14; reset: SWITCH_ON_DISABLED by T15')

        # Node 2: an axis of its own, set up by its own master; its Shutdown leaves node 1 alone.
        wait_state(base + '', lambda s: True, 'axis 1')
        deadline = time.monotonic() + 10
        while True:
            _, s2 = request(base + 'api/state?axis=2')
            if s2['remote']['status'] == 'running' or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        assert s2['remote']['status'] == 'running' and s2['remote']['node'] == 2, s2['remote']
        status, reply = request(base + 'api/command?axis=2', {'command': 'shutdown'})
        assert status == 200, (status, reply)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            _, axes = request(base + 'api/axes')
            if axes[1]['state'] == 'READY_TO_SWITCH_ON':
                break
            time.sleep(0.05)
        assert [a['label'] for a in axes] == ['node 1', 'node 2'], axes
        assert axes[1]['state'] == 'READY_TO_SWITCH_ON', axes
        assert axes[0]['state'] == 'SWITCH_ON_DISABLED', axes
        _, rec = request(base + 'api/recording')
        numbers = [t['number'] for t in rec['transitions']]
        assert numbers[-6:] == [2, 3, 4, 13, 14, 15] or numbers[-5:] == [3, 4, 13, 14, 15], numbers
        assert all(t['inferred'] for t in rec['transitions']), rec['transitions']
        _, rec2 = request(base + 'api/recording?axis=2')
        assert [t['number'] for t in rec2['transitions']] == [2], rec2['transitions']
        checks += 1
        print('ok 5 - node 2 is an axis of its own; the recorder holds each node\'s inferred transitions')

        assert bus.stop() == 0, bus.output
        s = wait_state(base, lambda s: s['remote']['status'] != 'running', 'the bus going away')
        assert s['state'] == 'UNKNOWN', s['state']
        assert s['remote']['text'], s['remote']
        status, reply = request(base + 'api/command', {'command': 'shutdown'})
        assert status == 503, (status, reply)
        checks += 1
        print(f"ok 6 - bus gone: the page says \"{s['remote']['text']}\", commands get 503")

        assert serve.stop() == 0, serve.output
        print(f'{checks} checks passed')
        return 0


if __name__ == '__main__':
    sys.exit(main())
