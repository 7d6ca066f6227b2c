"""The python-can bus on a cia402.canopen.VirtualBus (imported only when python-can is wanted).

Debian's python3-can provides `can`; nothing here opens a socket: the frames go straight to the
virtual drives in this process and back.
"""
from __future__ import annotations

import time
from typing import Any, Optional, Tuple

import can

from ._errors import ArgumentError


class VirtualCanBus(can.BusABC):
    """A python-can bus (can.BusABC) attached to a cia402.canopen.VirtualBus.

    Frames it sends reach every drive on the bus and every other attached bus; it receives every
    frame the drives and the other buses send (a CAN controller does not receive its own).
    Received messages carry the wall-clock time they were taken off the bus (time.time()). Filters
    (`can_filters`) are python-can's own, applied in Python.
    """

    def __init__(self, port: Any, channel: str = "cia402-virtual", **kwargs: Any) -> None:
        self._port = port
        self.channel_info = f"cia402 virtual CAN bus ({channel})"
        super().__init__(channel=channel, **kwargs)
        self.channel = channel

    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        """Puts `msg` on the bus at once (the virtual bus never blocks a sender)."""
        if msg.is_fd or msg.is_error_frame:
            raise can.CanOperationError("the virtual CANopen bus carries classic CAN data and remote frames only")
        try:
            self._port.send(msg.arbitration_id, bytes(msg.data), msg.is_extended_id,
                            msg.is_remote_frame, msg.dlc)
        except ArgumentError as e:
            raise can.CanOperationError(str(e)) from e

    def _recv_internal(self, timeout: Optional[float]) -> Tuple[Optional[can.Message], bool]:
        got = self._port.recv(timeout)
        if got is None:
            return None, False
        arbitration_id, data, extended, remote, dlc = got
        msg = can.Message(timestamp=time.time(), arbitration_id=arbitration_id, data=data,
                          is_extended_id=extended, is_remote_frame=remote, dlc=dlc,
                          channel=self.channel, is_rx=True)
        return msg, False

    def shutdown(self) -> None:
        """Detaches from the virtual bus; the drives go on."""
        super().shutdown()
        self._port.close()
