"""Reading a file someone else made (a policy, a checkpoint, a dataset): a regular file only,
and no larger than such a file can be.

A FIFO in a file's place blocks whoever opens it for reading (the open waits for a writer),
and a link to ``/dev/zero`` or ``/dev/urandom`` never ends (the read fills memory until the
process dies). ``read_regular`` looks before it reads: the path, links followed (a dataset
may link a file), must be a regular file of at most ``limit`` bytes; it is opened without
blocking and looked at again through the open file, so a file swapped in between is caught
too. Anything else is a ``NotRegularFileError`` naming the file, what it is and the fix.
``check_regular`` is the same check for a file another library reads (pyarrow,
safetensors), and ``regular_problem`` the check's finding, for a list of problems.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from gymfg_il.errors import ConfigError

MB, GB = 1 << 20, 1 << 30
JSON_LIMIT = 64 * MB  # a config or a dataset's metadata (kilobytes; statistics a few MB)
PARQUET_LIMIT = 16 * GB  # a dataset's table (LeRobot starts a new data file at 100 MB)
WEIGHTS_LIMIT = 64 * GB  # a policy's weights (ours: megabytes; pi0's: gigabytes)
VIDEO_LIMIT = 64 * GB  # a dataset's camera video
LOG_LIMIT = 64 * GB  # a trajectory log (read whole into memory)
NONBLOCK = getattr(os, "O_NONBLOCK", 0)  # an open that never waits for a FIFO's writer
CLOEXEC = getattr(os, "O_CLOEXEC", 0)


class NotRegularFileError(ConfigError):
    """A file GymFG was to read that is not a regular file (a FIFO, a device, a folder, a
    socket) or is larger than any such file; refused before it is read."""


def regular_problem(path: Path, limit: int) -> str | None:
    """What keeps ``path`` (links followed) from being read as a file of at most ``limit``
    bytes (``is a FIFO, not a regular file``, ``is N bytes, more than ...``), or None: it is one,
    or nothing is there (the caller says what is missing)."""
    try:
        return _problem(os.stat(path), limit)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as err:
        return f"cannot be read ({err.strerror})"


def read_regular(path: Path, limit: int, fix: str) -> bytes:
    """The bytes of the regular file at ``path`` (links followed) of at most ``limit``
    bytes, as many as it held when opened. FileNotFoundError where nothing is there; else
    NotRegularFileError naming ``path``, what is wrong and ``fix``."""
    fd = _open(Path(path), limit, fix)
    with open(fd, "rb") as f:
        return f.read(os.fstat(fd).st_size)


def check_regular(path: Path, limit: int, fix: str) -> int:
    """The size of the regular file at ``path``, checked as ``read_regular`` checks it,
    for a file another library opens; the same errors."""
    fd = _open(Path(path), limit, fix)
    try:
        return os.fstat(fd).st_size
    finally:
        os.close(fd)


def _open(path: Path, limit: int, fix: str) -> int:
    """An open descriptor of the file at ``path``, after its kind and size were checked
    before the open (opening a device may already act) and through it (a file swapped in
    between)."""
    try:
        found = _problem(os.stat(path), limit)
        fd = None if found else os.open(path, os.O_RDONLY | NONBLOCK | CLOEXEC)
    except (FileNotFoundError, NotADirectoryError):
        raise FileNotFoundError(errno.ENOENT, "no such file", str(path)) from None
    except OSError as err:
        raise NotRegularFileError(f"{path} cannot be read ({err.strerror}); {fix}") from None
    if fd is not None:
        found = _problem(os.fstat(fd), limit)
        if not found:
            return fd
        os.close(fd)
    raise NotRegularFileError(f"{path} {found}; {fix}")


def _problem(st: os.stat_result, limit: int) -> str | None:
    if not stat.S_ISREG(st.st_mode):
        return f"is {_kind(st.st_mode)}, not a regular file"
    if st.st_size > limit:
        return f"is {st.st_size} bytes, more than the {_size(limit)} GymFG reads of such a file"
    return None


def _size(n: int) -> str:
    return f"{n / GB:g} GB" if n >= GB else f"{n / MB:g} MB" if n >= MB else f"{n} bytes"


def _kind(mode: int) -> str:
    kinds = {stat.S_ISDIR: "a folder", stat.S_ISFIFO: "a FIFO", stat.S_ISCHR: "a device"}
    kinds |= {stat.S_ISBLK: "a device", stat.S_ISSOCK: "a socket"}
    return next((what for test, what in kinds.items() if test(mode)), "not a file")
