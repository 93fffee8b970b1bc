"""Output locations checked before any work: a folder (``--out DIR``) or a file (``--out FILE``,
``--json FILE``) must be creatable and writable, so that a long computation never ends in a
traceback at the moment it tries to save.  Nothing is created by the checks themselves (a probe
file is made and removed in the nearest existing folder)."""

from __future__ import annotations

import errno
import fcntl
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

from ..errors import SpacepolError


class OutputPathError(SpacepolError):
    """An output location that cannot be used."""


def _nearest_existing(path: Path) -> Path:
    for candidate in (path, *path.parents):
        if candidate.exists() or candidate.is_symlink():
            return candidate
    return Path(".")


def _probe_writable(folder: Path, option: str, path: Path) -> None:
    try:
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".spacepol-probe-")
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno else str(exc)
        raise OutputPathError(f"{option} {path}: cannot write in {folder} ({reason.lower()})") from None
    os.close(fd)
    os.unlink(probe)


def _check_parents(path: Path, option: str) -> None:
    existing = _nearest_existing(path.parent if path.parent != path else path)
    if not existing.is_dir():
        raise OutputPathError(f"{option} {path}: {existing} is a file, so nothing can be made under it")
    _probe_writable(existing, option, path)


def check_output_dir(path, option: str = "--out") -> Path:
    """A folder that exists and is writable, or can be made: else one line naming the problem."""
    path = Path(path)
    if str(path).strip() == "":
        raise OutputPathError(f"{option}: empty path")
    if path.exists() and not path.is_dir():
        raise OutputPathError(f"{option} {path}: is a file, not a folder")
    if path.is_dir():
        _probe_writable(path, option, path)
    else:
        _check_parents(path, option)
    return path


def check_output_file(path, option: str = "--out") -> Path:
    """A file path whose folder exists or can be made and is writable, and that is not a folder."""
    text = str(path)
    if text.strip() == "" or text.endswith(("/", os.sep)):
        raise OutputPathError(f"{option} {text}: give a file name, not a folder")
    path = Path(path)
    if path.is_dir():
        raise OutputPathError(f"{option} {path}: is a folder; give a file name")
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputPathError(f"{option} {path}: the file exists and is not writable")
    _check_parents(path, option)
    return path


@contextmanager
def folder_lock(folder, what: str = "run"):
    """Hold ``folder/.spacepol.lock`` for the duration (a second run on the folder gets one clear line).

    An advisory ``flock``: released by the kernel when the process dies, so a killed run never
    leaves a stale lock behind."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lock_path = folder / ".spacepol.lock"
    handle = open(lock_path, "a+")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        handle.seek(0)
        holder = handle.read().strip() or "unknown"
        handle.close()
        if exc.errno in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
            raise OutputPathError(f"{folder}: in use by another invert-mcmc {what} (process {holder}); "
                                  f"wait for it to finish or use another --out") from None
        raise
    try:
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        yield folder
    finally:
        try:
            lock_path.unlink(missing_ok=True)
        finally:
            handle.close()  # closing releases the flock
