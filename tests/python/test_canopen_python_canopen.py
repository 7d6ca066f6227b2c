"""python-canopen's BaseNode402 on cia402.canopen.VirtualBus, as its documentation shows it: the
drive's default PDOs, no SYNC. Skipped where python-canopen is not installed (it is not a Debian
package; run it by hand with a copy on PYTHONPATH, docs/python.md). test_canopen_basenode402.py
runs the same walk in CI with python-can doing what BaseNode402 does."""
import pytest

from cia402.canopen import VirtualBus

canopen = pytest.importorskip("canopen")

NODE = 1


@pytest.fixture
def node(tmp_path):
    with VirtualBus(nodes=[NODE]) as bus:
        eds = tmp_path / "drive.eds"
        eds.write_text(bus.eds(NODE))
        network = canopen.Network(bus=bus.python_can_bus())
        network.connect()
        try:
            drive = canopen.BaseNode402(NODE, str(eds))
            network.add_node(drive)
            drive.nmt.state = "PRE-OPERATIONAL"
            drive.setup_402_state_machine()
            drive.nmt.state = "OPERATIONAL"
            yield drive
        finally:
            network.disconnect()


def test_basenode402_walks_to_operation_enabled_and_back(node):
    node.state = "SWITCH ON DISABLED"
    node.state = "OPERATION ENABLED"
    assert node.state == "OPERATION ENABLED"
    node.state = "SWITCH ON DISABLED"
    assert node.state == "SWITCH ON DISABLED"


def test_basenode402_switches_the_mode_while_enabled_and_stays_enabled(node):
    node.op_mode = "PROFILED POSITION"
    node.state = "OPERATION ENABLED"
    node.op_mode = "PROFILED VELOCITY"
    assert node.op_mode == "PROFILED VELOCITY"
    assert node.state == "OPERATION ENABLED"


def test_basenode402_homes_with_method_37(node):
    node.sdo[0x6098].raw = 37
    node.state = "OPERATION ENABLED"
    node.op_mode = "PROFILED POSITION"  # while enabled: by SDO, the drive stays enabled
    assert node.homing(timeout=5) is True
    assert node.state == "OPERATION ENABLED"


def test_basenode402_resets_a_fault(node):
    node.state = "OPERATION ENABLED"
    node.sdo[0x2001].raw = 0x2310  # fault injection: continuous over-current
    node.sdo[0x2001].raw = 0       # the cause gone; the fault stays until reset
    node.check_statusword()
    assert node.is_faulted()
    node.reset_from_fault()
    assert not node.is_faulted()
    assert node.state == "OPERATION ENABLED"
