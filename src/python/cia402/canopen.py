"""cia402.canopen: the virtual CAN bus of `cia402 bus` with its virtual CiA 402 drives in this process.

    bus = cia402.canopen.VirtualBus(nodes=2, profile="cia402")   # drives on node 1 and 2
    can_bus = bus.python_can_bus()        # a can.BusABC: python-can and python-canopen use it
    network = canopen.Network(bus=can_bus)

On wall time (the default) a thread of the package steps the drives every millisecond, as
`cia402 bus` does; with virtual_time=True nothing moves until advance(ms). bus.axis(node) is the
project's master for a drive (Axis: enable, mode, move, home, velocity, sdo_read/sdo_write).
See docs/python.md.
"""
from __future__ import annotations

from typing import Any

from ._cia402 import canopen as _canopen

Axis = _canopen.Axis
Port = _canopen.Port


class VirtualBus(_canopen.VirtualBus):
    """The virtual CAN bus with virtual CiA 402 drives on it, in this process.

    VirtualBus(nodes=1, profile=None, *, virtual_time=False, period_ms=1.0, heartbeat_ms=0):
    `nodes` is a count (node-IDs 1..N) or an iterable of node-IDs; `profile` a built-in profile's
    name or a Profile (None: the standard one). Each drive is the node `cia402 bus` serves: the
    drive's objects, CiA 402's predefined PDO set (RPDO2 not valid until a master makes it so) and
    the SDO server. On wall time a thread steps the drives every `period_ms`; on virtual time
    advance(ms) does. A context manager: leaving it closes the bus.
    """

    def python_can_bus(self, **kwargs: Any) -> Any:
        """A python-can bus (a can.BusABC subclass) on this bus: `canopen.Network(bus=...)` and any
        python-can code run against the drives with no socket. Keyword arguments go to
        can.BusABC (e.g. can_filters). ImportError when python-can is not installed."""
        from ._python_can import VirtualCanBus
        return VirtualCanBus(self.attach(), **kwargs)

    def __enter__(self) -> "VirtualBus":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


__all__ = ["Axis", "Port", "VirtualBus"]
