"""User-facing errors: one clear line naming what is wrong and where."""

from __future__ import annotations


class SpacepolError(Exception):
    """Base class for errors caused by user input (files, names, values).

    The CLI prints ``str(error)`` on one line and exits with status 2.
    """


class InputFileError(SpacepolError):
    """A measurement or geometry file is malformed."""

    def __init__(self, path, message: str, line: int | None = None, column: str | None = None):
        where = str(path)
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column '{column}'"
        super().__init__(f"{where}: {message}")
        self.path, self.line, self.column = path, line, column


class UnknownNameError(SpacepolError):
    """An effect, preset, method or parameter name that is not registered."""


class ParameterError(SpacepolError):
    """An impossible or inconsistent parameter value or prior."""


class SamplerStalled(Exception):
    """A sampler stopped making progress and was stopped (``infer.engines.stall_guard``): not the input's fault, so
    not a SpacepolError; the CLI prints its one line and exits with status 1."""
