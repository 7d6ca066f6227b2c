"""The exceptions of the cia402 package: one hierarchy, every one a cia402.Error.

The C++ layer raises these from its results (an SDO abort code, a refused file, a refused
argument); it never lets a C++ exception or a crash through.
"""
from __future__ import annotations

from typing import Optional


class Error(Exception):
    """Every error the cia402 package raises."""


class ArgumentError(Error, ValueError):
    """An argument the package refuses: an unknown state, mode or profile name, a value out of its
    range, an unknown or unusable plant setting. Nothing was changed."""


class SdoError(Error):
    """An object access the drive refused, with its CiA 301 SDO abort code (`code`, e.g.
    0x06090030) and the code's text (`text`, e.g. "invalid value for parameter"). Nothing was
    changed."""

    def __init__(self, code: int, text: str, index: Optional[int] = None, sub: int = 0,
                 action: str = "") -> None:
        self.code = code
        self.text = text
        self.index = index
        self.sub = sub
        where = ""
        if index is not None:
            where = f" {action + ' ' if action else ''}0x{index:04X}:{sub}"
        super().__init__(f"SDO abort 0x{code:08X} ({text}){where}")


class FileError(Error):
    """A file (or text) that does not parse, with the 1-based `line` and `column` of the mistake
    (0: the whole file, e.g. it could not be read), the `reason` and the `source` name."""

    def __init__(self, line: int, column: int, reason: str, source: str, message: str) -> None:
        self.line = line
        self.column = column
        self.reason = reason
        self.source = source
        super().__init__(message)


class ProfileError(FileError):
    """A profile file refused, or a profile name that is not built in (line 0)."""


class ScenarioError(FileError):
    """A simulator scenario refused."""


class AxisError(Error):
    """A request of the master (cia402.canopen.Axis) that failed or did not end in time, in words,
    with the `state` the drive showed at the end (None where not known), its `status_word` and its
    `error_code` (0x603F). An object the drive refused raises SdoError instead."""

    def __init__(self, message: str, state: Optional[str] = None, status_word: int = 0,
                 error_code: int = 0) -> None:
        self.state = state
        self.status_word = status_word
        self.error_code = error_code
        super().__init__(message)


class BusyError(Error):
    """A machine was used from a second thread while it advanced on another (the GIL is released
    while a machine steps)."""


# Shown as cia402.SdoError (the package exports them), not as the private module they live in.
for _cls in (Error, ArgumentError, SdoError, FileError, ProfileError, ScenarioError, BusyError,
             AxisError):
    _cls.__module__ = "cia402"
del _cls
