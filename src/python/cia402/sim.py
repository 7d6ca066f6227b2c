"""cia402.sim: machines of N virtual drives (the core plus a plant in every operation mode) on
virtual time, their traces, and scenarios from TOML.

Columns and bulk reads are NumPy arrays where NumPy is installed, and lists otherwise.
"""
from __future__ import annotations

import array
from typing import Any, List, Union

from ._cia402 import sim as _sim

Axis = _sim.Axis
LogEntry = _sim.LogEntry
Machine = _sim.Machine
Scenario = _sim.Scenario
ScenarioResult = _sim.ScenarioResult
Trace = _sim.Trace
load_scenario = _sim.load_scenario
run_scenario = _sim.run_scenario

__all__ = [
    "Axis",
    "LogEntry",
    "Machine",
    "Scenario",
    "ScenarioResult",
    "Trace",
    "load_scenario",
    "numpy_available",
    "run_scenario",
]

_DTYPES = {"q": "int64", "d": "float64", "?": "bool"}
_numpy: Any = None
_numpy_looked_for = False


def _numpy_module() -> Any:
    """NumPy, or None when it is not installed; looked for once, at the first column."""
    global _numpy, _numpy_looked_for
    if not _numpy_looked_for:
        try:
            import numpy
        except ImportError:
            numpy = None
        _numpy = numpy
        _numpy_looked_for = True
    return _numpy


def numpy_available() -> bool:
    """Whether columns come as NumPy arrays (True) or lists (False)."""
    return _numpy_module() is not None


def _column(typecode: str, data: Union[bytes, List[str]]) -> Any:
    """A column from the C++ layer: packed values ('q' int64, 'd' float64, '?' bool) or a list of
    str ('U'), as a NumPy array or a list."""
    numpy = _numpy_module()
    if typecode == "U":
        return numpy.array(data, dtype=str) if numpy is not None else list(data)
    assert isinstance(data, bytes)
    if numpy is not None:
        return numpy.frombuffer(data, dtype=_DTYPES[typecode]).copy()
    if typecode == "?":
        return [byte != 0 for byte in data]
    return array.array(typecode, data).tolist()
