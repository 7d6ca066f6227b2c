#!/usr/bin/env python3
"""Soak test, bounded in time (about 40 s), as CI runs it:  soak.py CIA402_BINARY

bus: 12 clients in raw mode each send 400 numbered frames while one listener counts them, and
misbehaving clients connect and leave at once, send garbage, open a wrong bus or never read. Every
numbered frame must reach the listener, the bus's memory must stay flat.

serve: 4 threads send 1,000 commands (toggles of control-word bit 11, which the state machine does
not read) while 10 slow clients dribble request heads beside them. Every command must be taken
(200, a new result id each), the bit must end where 1,000 toggles leave it, the page must answer
every 100 ms probe within 1 s, and the server's memory must stay flat.

Prints the figures; exits 1 on the first broken promise."""
import http.client
import json
import os
import re
import socket
import subprocess
import sys
import threading
import time


def rss_kb(pid):
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    return 0


class Process:
    def __init__(self, args):
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.output = ''

    def wait_for(self, pattern, timeout=15):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            self.output += line
            m = re.search(pattern, self.output)
            if m:
                return m
        raise AssertionError(f'{pattern!r} not printed:\n{self.output}')

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        return self.proc.returncode


def check(ok, message):
    if not ok:
        raise AssertionError(message)


# --- bus ----------------------------------------------------------------------------------------

def join_raw(port):
    s = socket.create_connection(('127.0.0.1', port), timeout=5)
    s.settimeout(5)
    buf = b''
    for want, send in ((b'< hi >', b'< open can0 >'), (b'< ok >', b'< rawmode >'), (b'< ok >', None)):
        while want not in buf:
            chunk = s.recv(4096)
            check(chunk, 'the bus closed a joining client')
            buf += chunk
        buf = buf[buf.index(want) + len(want):]
        if send:
            s.sendall(send)
    return s, buf


def soak_bus(cia402):
    bus = Process([cia402, 'bus', '--listen', '127.0.0.1:0', '--nodes', '1-4'])
    port = int(bus.wait_for(r'socketcand on 127\.0\.0\.1:(\d+)').group(1))
    time.sleep(0.3)
    rss_before = rss_kb(bus.proc.pid)
    senders, per_sender = 12, 400
    listener, pending = join_raw(port)
    time.sleep(0.3)  # past the join grace
    seen = {k: set() for k in range(senders)}
    stop = threading.Event()

    def listen():
        nonlocal pending
        listener.settimeout(0.5)
        data = pending
        while not stop.is_set():
            try:
                chunk = listener.recv(65536)
            except socket.timeout:
                continue
            if not chunk:
                break
            data += chunk
            *elements, data = data.split(b'>')
            for e in elements:
                m = re.search(rb'< frame (1[0-9A-F]{2}) [0-9.]+ ([0-9A-F]{4})', e + b'>')
                if m and 0x100 <= int(m.group(1), 16) < 0x100 + senders:
                    seen[int(m.group(1), 16) - 0x100].add(int(m.group(2), 16))

    def send(k):
        s, _ = join_raw(port)
        time.sleep(0.2)
        for n in range(per_sender):
            s.sendall(f'< send {0x100 + k:X} 2 {n >> 8:02X} {n & 0xFF:02X} >'.encode())
            if n % 50 == 49:
                time.sleep(0.01)
        time.sleep(0.5)
        s.close()

    def misbehave(i):
        kinds = ['close', 'garbage', 'wrong bus', 'no read', 'half']
        for n in range(30):
            kind = kinds[(i + n) % len(kinds)]
            try:
                s = socket.create_connection(('127.0.0.1', port), timeout=2)
                if kind == 'garbage':
                    s.sendall(b'\x00\xff< bogus >' + os.urandom(300) + b'< send zz >')
                elif kind == 'wrong bus':
                    s.sendall(b'< open can9 >')
                elif kind == 'no read':
                    s.sendall(b'< open can0 >< rawmode >')
                    time.sleep(0.2)
                elif kind == 'half':
                    s.sendall(b'< open can0 >< send 12')
                s.close()
            except OSError:
                pass
            time.sleep(0.05)

    t_listen = threading.Thread(target=listen)
    t_listen.start()
    threads = [threading.Thread(target=send, args=(k,)) for k in range(senders)]
    threads += [threading.Thread(target=misbehave, args=(i,)) for i in range(2)]
    started = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    time.sleep(1.0)
    stop.set()
    t_listen.join()
    listener.close()
    rss_after = rss_kb(bus.proc.pid)
    delivered = sum(len(v) for v in seen.values())
    sent = senders * per_sender
    print(f'soak bus: {sent} numbered frames sent by {senders} clients, {delivered} delivered, '
          f'60 misbehaving connections; RSS {rss_before} kB -> {rss_after} kB; '
          f'{time.monotonic() - started:.1f} s')
    check(delivered == sent, f'frames lost: {[per_sender - len(v) for v in seen.values()]}')
    check(rss_after - rss_before < 20000, 'the bus grew by more than 20 MB')
    check(bus.stop() == 0, bus.output)


# --- serve --------------------------------------------------------------------------------------

def post(port, body, conn=None):
    c = conn or http.client.HTTPConnection('127.0.0.1', port, timeout=10)
    c.request('POST', '/api/command', json.dumps(body), {'Content-Type': 'application/json'})
    r = c.getresponse()
    data = r.read()
    return r.status, json.loads(data)


def soak_serve(cia402):
    serve = Process([cia402, 'serve', '--port', '0'])
    base = serve.wait_for(r'instrument page at http://127\.0\.0\.1:(\d+)/')
    port = int(base.group(1))
    time.sleep(0.3)
    rss_before = rss_kb(serve.proc.pid)
    stop = threading.Event()
    ids, statuses, worst = [], [], [0.0]
    lock = threading.Lock()

    def slow(i):
        while not stop.is_set():
            try:
                s = socket.create_connection(('127.0.0.1', port), timeout=5)
                s.sendall(b'GET /api/state HTTP/1.1\r\n')
                for _ in range(20):
                    if stop.is_set():
                        break
                    time.sleep(0.5)
                    s.sendall(b'X-Slow: 1\r\n')
                s.close()
            except OSError:
                time.sleep(0.1)

    def flood(k):
        conn = http.client.HTTPConnection('127.0.0.1', port, timeout=10)
        for _ in range(250):
            try:
                status, reply = post(port, {'command': 'toggle_bit', 'bit': 11}, conn)
            except (OSError, http.client.HTTPException):
                conn = http.client.HTTPConnection('127.0.0.1', port, timeout=10)
                status, reply = post(port, {'command': 'toggle_bit', 'bit': 11}, conn)
            with lock:
                statuses.append(status)
                ids.append(reply.get('id'))

    def probe():
        while not stop.is_set():
            t0 = time.monotonic()
            c = http.client.HTTPConnection('127.0.0.1', port, timeout=10)
            c.request('GET', '/api/state')
            c.getresponse().read()
            worst[0] = max(worst[0], time.monotonic() - t0)
            time.sleep(0.1)

    slow_threads = [threading.Thread(target=slow, args=(i,)) for i in range(10)]
    probe_thread = threading.Thread(target=probe)
    for t in slow_threads + [probe_thread]:
        t.start()
    time.sleep(0.5)
    started = time.monotonic()
    floods = [threading.Thread(target=flood, args=(k,)) for k in range(4)]
    for t in floods:
        t.start()
    for t in floods:
        t.join()
    took = time.monotonic() - started
    time.sleep(0.5)
    stop.set()
    for t in slow_threads + [probe_thread]:
        t.join()
    c = http.client.HTTPConnection('127.0.0.1', port, timeout=10)
    c.request('GET', '/api/state')
    state = json.loads(c.getresponse().read())
    rss_after = rss_kb(serve.proc.pid)
    taken = sum(1 for s in statuses if s == 200)
    print(f'soak serve: {len(statuses)} commands sent, {taken} taken ({len(set(ids))} distinct ids) '
          f'in {took:.1f} s beside 10 slow clients; worst page probe {worst[0] * 1000:.0f} ms; '
          f'RSS {rss_before} kB -> {rss_after} kB')
    check(taken == 1000 and len(set(ids)) == 1000, 'commands lost or refused')
    check(int(state['control_word'], 16) & 0x0800 == 0, '1,000 toggles of bit 11 did not end at 0')
    check(worst[0] < 1.0, 'the page took more than 1 s to answer')
    check(rss_after - rss_before < 20000, 'serve grew by more than 20 MB')
    check(serve.stop() == 0, serve.output)


def main():
    if len(sys.argv) != 2:
        print('usage: soak.py CIA402_BINARY', file=sys.stderr)
        return 2
    soak_bus(sys.argv[1])
    soak_serve(sys.argv[1])
    return 0


if __name__ == '__main__':
    sys.exit(main())
