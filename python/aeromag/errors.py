"""The exceptions aeromag raises.

- :class:`BadInputError` (a :class:`ValueError`): the input cannot be used
  — a missing or mis-mapped column, a value in the wrong unit, a NaN where
  a value is needed, time going backwards, a damaged file, an invalid
  option. It carries where: ``file``, ``line`` (1-based line of a text
  file), ``row`` (0-based data row of the file: the index into the file's
  rows, whatever rows a ``lines=`` selection kept) and ``column``, each
  ``None`` when not known. The CLI exits with code 2 on these.
- :class:`AeromagError`: valid input on which a method failed (a fit that
  did not converge, a flight that does not determine the model, …).
- :class:`OSError`: an output file could not be written.

And the warning it raises:

- :class:`AeromagWarning` (a :class:`UserWarning`): a model was applied to
  a flight that does not quite look like its calibration (another sample
  rate, dropouts bridged), as the CLI warns; the results are computed.
  Results of fits carry their warnings in ``notes`` instead.
"""

from __future__ import annotations

from typing import Optional


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


class AeromagWarning(UserWarning):
    """A model applied to a flight that does not quite fit it (the CLI's
    "warning: …" lines): raised with :func:`warnings.warn`."""
