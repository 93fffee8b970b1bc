"""Checks of single cells and rows of a measurement file, shared by the spacepol CSV reader and NIST's layout: each
problem is one :class:`InputFileError` naming file, line and column."""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError


def parse_number(text, path, line, column) -> float:
    """The cell's finite number, or an error naming where it is."""
    try:
        value = float(text)
    except ValueError:
        shown = text if text.strip() else "(empty)"
        raise InputFileError(path, f"'{shown}' is not a number", line=line, column=column) from None
    if not np.isfinite(value):
        raise InputFileError(path, f"'{text}' is not a finite number", line=line, column=column)
    return value


def is_blank_row(row: list[str], path, line) -> bool:
    """Whether a parsed CSV row is a blank line (no separator, at most whitespace), which readers skip. A row of
    separators alone is not blank: its fields are empty, an error naming the line."""
    if all(not cell.strip() for cell in row):
        if len(row) > 1:
            raise InputFileError(path, "a row of empty fields (only separators): no values", line=line)
        return True
    return False
