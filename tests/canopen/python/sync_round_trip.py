"""Measures what a cyclic master over python-can's socketcand client sees from `cia402 bus`: each
cycle sends an RPDO (RPDO3: control word + target position, taken at the next SYNC) and then a SYNC,
and waits for the TPDO the SYNC triggers (TPDO3, sent on every SYNC). python-can 4.1's client does
not set TCP_NODELAY, so its SYNC waits in the client's kernel (Nagle) until the server ACKs the
RPDO; a server that delays its ACKs makes that wait up to 40 ms. Prints the round trips and the
cycle periods; asserts nothing about time (a loaded machine is slow), so it is a measurement, not a
test.

    python3 sync_round_trip.py CIA402_BINARY [CYCLES] [PERIOD_MS]
"""
import statistics
import subprocess
import sys
import time

import can

NODE = 1


def main():
    binary = sys.argv[1]
    cycles = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    period = (float(sys.argv[3]) if len(sys.argv) > 3 else 5.0) / 1000
    proc = subprocess.Popen([binary, "bus", "--listen", "127.0.0.1:0", "--nodes", str(NODE)],
                            stdout=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    port = int(line.split("127.0.0.1:")[1].split()[0])
    bus = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
    try:
        time.sleep(0.15)
        bus.send(can.Message(arbitration_id=0x000, data=[0x01, NODE], is_extended_id=False))
        time.sleep(0.1)
        while bus.recv(timeout=0) is not None:
            pass
        round_trips, periods, lost = [], [], 0
        last_start = None
        next_tick = time.monotonic()
        for i in range(cycles):
            now = time.monotonic()
            if now < next_tick:
                time.sleep(next_tick - now)
            start = time.monotonic()
            if last_start is not None:
                periods.append(start - last_start)
            last_start = start
            next_tick = start + period
            rpdo3 = (0x0006).to_bytes(2, "little") + (i * 10).to_bytes(4, "little", signed=True)
            bus.send(can.Message(arbitration_id=0x400 + NODE, data=rpdo3, is_extended_id=False))
            bus.send(can.Message(arbitration_id=0x080, data=[], is_extended_id=False))
            end = start + 0.2
            got = None
            while time.monotonic() < end:
                msg = bus.recv(timeout=max(0.0, end - time.monotonic()))
                if msg is not None and msg.arbitration_id == 0x380 + NODE:
                    got = msg
                    break
            if got is None:
                lost += 1
                continue
            round_trips.append(time.monotonic() - start)
        ms = [t * 1000 for t in round_trips]
        pm = [t * 1000 for t in periods]
        print("cycles %d, period asked %.1f ms, TPDO3 lost %d" % (cycles, period * 1000, lost))
        print("round trip RPDO+SYNC -> TPDO3 ms: min %.2f median %.2f p90 %.2f max %.2f"
              % (min(ms), statistics.median(ms), sorted(ms)[int(len(ms) * 0.9)], max(ms)))
        print("cycle period ms: min %.2f median %.2f p90 %.2f max %.2f"
              % (min(pm), statistics.median(pm), sorted(pm)[int(len(pm) * 0.9)], max(pm)))
    finally:
        bus.shutdown()
        proc.terminate()
        proc.wait(timeout=5)


if __name__ == "__main__":
    main()
