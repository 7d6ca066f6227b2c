"""A python-can session that brings drive 1 of a running `cia402 bus` to OPERATION ENABLED, printing
every frame it sends and receives. Not a test (pytest does not collect it); for people:
    cia402 bus --listen 127.0.0.1:29536 &
    /usr/bin/python3 tests/canopen/python/demo_session.py 29536
"""
import sys
import time

import can

port = int(sys.argv[1]) if len(sys.argv) > 1 else 29536
bus = can.Bus(interface="socketcand", channel="can0", host="127.0.0.1", port=port)
time.sleep(0.15)


def show(direction, msg):
    print("%s %03X [%d] %s" % (direction, msg.arbitration_id, len(msg.data),
                               " ".join("%02X" % b for b in msg.data)))


def send(cob_id, data, note):
    msg = can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False)
    bus.send(msg)
    show("->", msg)
    print("   # " + note)


def listen(seconds, ids):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        msg = bus.recv(timeout=end - time.monotonic())
        if msg is not None and msg.arbitration_id in ids:
            show("<-", msg)


send(0x601, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0], "SDO upload 0x1000 device type")
listen(0.1, {0x581})
send(0x601, [0x2B, 0x17, 0x10, 0x00, 0xF4, 0x01, 0, 0], "SDO download 0x1017 = 500 ms heartbeat")
listen(0.6, {0x581, 0x701})
send(0x000, [0x01, 0x01], "NMT start node 1")
listen(0.1, {0x181})
send(0x201, [0x06, 0x00], "RPDO1 control word 0x0006 Shutdown")
listen(0.1, {0x181})
send(0x201, [0x0F, 0x00], "RPDO1 control word 0x000F Enable operation")
listen(0.2, {0x181, 0x081})
send(0x601, [0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0], "SDO upload 0x6041 status word")
listen(0.1, {0x581})
bus.shutdown()
