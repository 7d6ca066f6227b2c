"""cia402: the CiA 402 drive state machine for hardware-less test benches.

A drive of any built-in or file profile on an ideal or simulated plant (Drive), the replay
interface of `cia402 replay` (Replay, Drive.replay), the master's planner (path), and in
cia402.sim machines of many virtual drives on virtual time with traces and scenarios; in
cia402.canopen the virtual CAN bus with its drives in process, for python-can and python-canopen,
and in cia402.ethercat a virtual EtherCAT line; on both, the project's master as Axis.
Errors are cia402.Error: SdoError carries the SDO abort code and its text. See docs/python.md.
"""
from ._cia402 import (
    Drive,
    Outputs,
    PathStep,
    Profile,
    Replay,
    __version__,
    objects,
    path,
    profiles,
    sdo_abort_text,
    states,
)
from ._errors import (
    ArgumentError,
    AxisError,
    BusyError,
    Error,
    FileError,
    ProfileError,
    ScenarioError,
    SdoError,
)
from . import canopen, ethercat, sim

__all__ = [
    "ArgumentError",
    "AxisError",
    "BusyError",
    "Drive",
    "Error",
    "FileError",
    "Outputs",
    "PathStep",
    "Profile",
    "ProfileError",
    "Replay",
    "ScenarioError",
    "SdoError",
    "__version__",
    "objects",
    "path",
    "profiles",
    "sdo_abort_text",
    "canopen",
    "ethercat",
    "sim",
    "states",
]
