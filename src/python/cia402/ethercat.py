"""cia402.ethercat: a chain of virtual EtherCAT drives and the project's master over it, in this
process and on virtual time.

    line = cia402.ethercat.VirtualLine(drives=2)   # brought to OP by the master
    axis = line.axis(0)                             # the master's Axis for the first drive
    axis.enable(); axis.move(10000)

See docs/python.md.
"""
from __future__ import annotations

from ._cia402 import ethercat as _ethercat

Axis = _ethercat.Axis
VirtualLine = _ethercat.VirtualLine

__all__ = ["Axis", "VirtualLine"]
