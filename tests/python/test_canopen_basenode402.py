"""What python-canopen's BaseNode402 does, done with python-can on cia402.canopen.VirtualBus with
the drive's default PDOs and no SYNC (CI has no python-canopen: it is not a Debian package;
test_canopen_python_canopen.py runs BaseNode402 itself where it is installed).

BaseNode402's waits, from python-canopen 2.x (canopen/profiles/p402.py): once it has seen two
TPDOs with the status word it takes that TPDO for periodic and waits TIMEOUT_CHECK_TPDO = 0.2 s for
each next one (check_statusword); 0x6061 likewise; a state takes at most 0.4 s per step. It maps
0x6060 through the first RPDO whose COB-ID is valid (bit 31 clear), else it writes 0x6060 by SDO.
The waits here are measured on the drives' clock (VirtualBus.time_ms), not the wall clock: on an
idle host the two agree, and a loaded CI host that holds up the bus's thread fails nothing.
Object numbers and bits are CiA 402-2's (0x6040 control word, 0x6041 status word, 0x6060/0x6061
modes), frames CiA 301's."""
import time

import pytest

from cia402.canopen import VirtualBus

can = pytest.importorskip("can")

NODE = 1
TPDO1, TPDO2 = 0x180 + NODE, 0x280 + NODE
RPDO1 = 0x200 + NODE
CHECK_TPDO_S = 0.2       # BaseNode402.TIMEOUT_CHECK_TPDO
SWITCH_STATE_S = 0.4     # BaseNode402.TIMEOUT_SWITCH_STATE_SINGLE
PDO_NOT_VALID = 0x80000000


# The states BaseNode402 names, by their status word bits (mask, value).
STATES = ((0x4F, 0x40, "SWITCH ON DISABLED"), (0x6F, 0x21, "READY TO SWITCH ON"), (0x6F, 0x23, "SWITCHED ON"),
          (0x6F, 0x27, "OPERATION ENABLED"), (0x4F, 0x08, "FAULT"))


def state_of(word):
    return next((name for mask, value, name in STATES if word & mask == value), f"0x{word:04X}")


class Node402:
    """The frames and waits of BaseNode402, over python-can."""

    def __init__(self, bus, virtual_bus):
        self.bus = bus
        self.clock = virtual_bus  # time_ms: the drives' time
        self.status_word = None
        self.op_mode = None

    def _take(self, msg):
        if msg.arbitration_id == TPDO1 and len(msg.data) == 2:
            self.status_word = int.from_bytes(msg.data[:2], "little")
        elif msg.arbitration_id == TPDO2 and len(msg.data) == 3:
            self.status_word = int.from_bytes(msg.data[:2], "little")
            self.op_mode = msg.data[2]

    def wait_for(self, cob_id, timeout):
        """The next frame of `cob_id` within `timeout` s of the drives' time (pdo.wait_for_reception),
        or None. Frames already queued are taken before the time is looked at."""
        end_ms = self.clock.time_ms + timeout * 1000
        give_up = time.monotonic() + 30  # a bus that stopped stepping altogether
        while True:
            msg = self.bus.recv(timeout=0.005)
            if msg is not None:
                self._take(msg)
                if msg.arbitration_id == cob_id:
                    return msg
                continue
            if self.clock.time_ms > end_ms or time.monotonic() > give_up:
                return None

    def check_statusword(self):
        assert self.wait_for(TPDO1, CHECK_TPDO_S) is not None, "Timeout waiting for updated statusword"
        return self.status_word

    def sdo(self, request):
        self.bus.send(can.Message(arbitration_id=0x600 + NODE, data=request, is_extended_id=False))
        msg = self.wait_for(0x580 + NODE, 0.5)
        assert msg is not None, "no SDO answer"
        assert msg.data[0] != 0x80, f"SDO abort 0x{int.from_bytes(msg.data[4:8], 'little'):08X}"
        return msg

    def sdo_read(self, index, sub=0):
        msg = self.sdo(bytes([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]))
        return int.from_bytes(msg.data[4:8], "little")

    def sdo_write(self, index, sub, value, size):
        command = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
        self.sdo(bytes([command, index & 0xFF, index >> 8, sub]) + value.to_bytes(4, "little", signed=value < 0))

    def controlword(self, word):
        self.bus.send(can.Message(arbitration_id=RPDO1, data=word.to_bytes(2, "little"), is_extended_id=False))

    def latest_status(self):
        """Every frame already queued taken: the status word the drive sent last."""
        while (msg := self.bus.recv(timeout=0)) is not None:
            self._take(msg)
        return self.status_word

    def until_state(self, state, end_ms, why):
        """check_statusword until the state shows, by `end_ms` of the drives' time. A test process
        held up on a loaded host finds status words queued from before the time was up: those are
        not late, so the last one queued decides."""
        while state_of(self.check_statusword()) != state:
            if self.clock.time_ms >= end_ms:
                assert state_of(self.latest_status()) == state, f"{why}: {state_of(self.status_word)}"
                return

    def go(self, word, state):
        """One step of BaseNode402's state setter: the control word by RPDO1, then check_statusword
        until the state shows, within 0.4 s."""
        self.controlword(word)
        self.until_state(state, self.clock.time_ms + SWITCH_STATE_S * 1000, f"not {state} within {SWITCH_STATE_S} s")

    def enable(self):
        self.go(0x06, "READY TO SWITCH ON")
        self.go(0x07, "SWITCHED ON")
        self.go(0x0F, "OPERATION ENABLED")


@pytest.fixture
def node():
    with VirtualBus(nodes=[NODE]) as bus, bus.python_can_bus() as can_bus:
        n = Node402(can_bus, bus)
        can_bus.send(can.Message(arbitration_id=0x000, data=[0x01, NODE], is_extended_id=False))  # NMT start
        # Two status TPDOs seen: from now on BaseNode402 takes TPDO1 for periodic.
        assert n.wait_for(TPDO1, 0.5) is not None
        assert n.wait_for(TPDO1, 0.5) is not None
        yield n


def test_an_unchanged_status_word_comes_within_basenode402s_wait_again_and_again(node):
    for _ in range(10):
        node.check_statusword()
        assert state_of(node.status_word) == "SWITCH ON DISABLED"
    assert node.wait_for(TPDO2, CHECK_TPDO_S) is not None, "0x6061's TPDO2 too"


def test_basenode402_finds_rpdo2_not_valid_and_switches_the_mode_by_sdo_while_enabled(node):
    # BaseNode402's setup_pdos reads each RPDO's COB-ID: RPDO2 (0x6040 + 0x6060) is not valid, so
    # 0x6060 goes by SDO and no stale copy of 0x6040 reaches the drive.
    assert node.sdo_read(0x1401, 1) & PDO_NOT_VALID
    assert node.sdo_read(0x1601, 1) >> 16 == 0x6040 and node.sdo_read(0x1601, 2) >> 16 == 0x6060
    assert node.sdo_read(0x1400, 1) == RPDO1, "RPDO1 carries the control word"
    node.sdo_write(0x6060, 0, 1, 1)  # pp
    node.enable()
    node.sdo_write(0x6060, 0, 3, 1)  # pv, while enabled
    end_ms = node.clock.time_ms + 500  # BaseNode402.TIMEOUT_SWITCH_OP_MODE, reading 0x6061 by TPDO2
    while node.op_mode != 3:
        assert node.wait_for(TPDO2, CHECK_TPDO_S) is not None
        assert node.clock.time_ms < end_ms, "0x6061 did not show pv"
    for _ in range(3):
        assert state_of(node.check_statusword()) == "OPERATION ENABLED"


def test_basenode402_homes_with_method_37_seeing_each_status_word_in_time(node):
    node.sdo_write(0x6098, 0, 37, 1)
    node.sdo_write(0x6060, 0, 6, 1)  # homing
    node.enable()
    node.controlword(0x1F)           # homing operation start (bit 4)
    end_ms = node.clock.time_ms + 5000
    while True:
        word = node.check_statusword()
        if word & (1 << 12) and word & (1 << 10):  # homing attained, target reached
            break
        assert not word & (1 << 13), "homing error"
        assert node.clock.time_ms < end_ms, "homing did not finish"
    node.controlword(0x0F)
    assert state_of(node.check_statusword()) == "OPERATION ENABLED"


def test_basenode402_resets_a_fault_and_walks_back_to_operation_enabled(node):
    node.enable()
    node.sdo_write(0x2001, 0, 0x2310, 2)  # fault injection: continuous over-current
    node.sdo_write(0x2001, 0, 0, 2)       # the cause gone; the fault stays until reset
    node.until_state("FAULT", node.clock.time_ms + SWITCH_STATE_S * 1000, "no fault")
    # reset_from_fault: Disable voltage, then the walk to OPERATION ENABLED (fault reset first).
    node.controlword(0x00)
    assert state_of(node.check_statusword()) == "FAULT", "no automatic restart"
    node.go(0x80, "SWITCH ON DISABLED")
    node.enable()
