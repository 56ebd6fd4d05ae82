"""The exceptions aeromag raises.

- :class:`BadInputError` (a :class:`ValueError`): the input cannot be used
  — a missing or mis-mapped column, a value in the wrong unit, a NaN where
  a value is needed, time going backwards, a damaged file, an invalid
  option. It carries where: ``file``, ``line`` (1-based line of a text
  file), ``row`` (0-based data row of the file: the index into the file's
  rows, whatever rows a ``lines=`` selection kept) and ``column``, each
  ``None`` when not known. The CLI exits with code 2 on these.
- :class:`MissingFileError` (a :class:`BadInputError` and a
  :class:`FileNotFoundError`): an input file that does not exist, with
  ``errno`` and ``filename`` as :func:`open` gives them.
- :class:`AeromagError`: valid input on which a method failed (a fit that
  did not converge, a flight that does not determine the model, …).
- :class:`OSError`: an output file could not be written; the subclass of
  its ``errno`` (``NotADirectoryError``, ``PermissionError``, …) with
  ``filename``, as :func:`open` raises it.

And the warning it raises:

- :class:`AeromagWarning` (a :class:`UserWarning`): a model was applied to
  a flight that does not quite look like its calibration (another sample
  rate, dropouts bridged), as the CLI warns; the results are computed.
  Results of fits carry their warnings in ``notes`` instead.
"""

from __future__ import annotations

import errno as _errno
import os as _os
from typing import Any, Optional


class AeromagError(Exception):
    """An aeromag method failed (the base class of aeromag's exceptions)."""

    def __init__(
        self,
        message: str,
        file: Optional[str] = None,
        line: Optional[int] = None,
        row: Optional[int] = None,
        column: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        #: The file concerned, if any.
        self.file = file
        #: 1-based line of a text file, if known.
        self.line = line
        #: 0-based data row of the file, if known.
        self.row = row
        #: The column concerned, if any.
        self.column = column


class BadInputError(AeromagError, ValueError):
    """The input (a file, an array, an option) cannot be used."""


class MissingFileError(BadInputError, FileNotFoundError):
    """An input file that does not exist (``except FileNotFoundError``
    catches it too): ``filename`` and ``file`` name it, ``errno`` is
    ``ENOENT``; ``str()`` is aeromag's message."""

    def __init__(self, message: str, *where: Any, **named: Any) -> None:
        super().__init__(message, *where, **named)
        self.errno = _errno.ENOENT
        self.strerror = _os.strerror(_errno.ENOENT)
        self.filename = self.file

    def __str__(self) -> str:
        return str(self.args[0])


def _os_error(message: str, errno: Optional[int], filename: Optional[str]) -> OSError:
    """The OSError of a file that could not be written: the subclass of
    ``errno`` with ``filename``, as :func:`open` raises it (``message``
    alone when the system gave no error number)."""
    if errno is None:
        return OSError(message)
    return OSError(errno, _os.strerror(errno), filename)


class AeromagWarning(UserWarning):
    """A model applied to a flight that does not quite fit it (the CLI's
    "warning: …" lines): raised with :func:`warnings.warn`."""
