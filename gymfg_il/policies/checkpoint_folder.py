"""A policy folder replaced whole: a kill at any moment leaves the old policy or the new one.

``train bc`` used to write ``config.json``, ``model.safetensors``, ``loss.png`` and
``train_log.json`` into the policy's folder one after another; killed (``kill -9``) while
saving over an older policy, it left the new config beside the old weights (which loaded as
a policy neither run trained) or a truncated config (the old policy gone). Now ``staged``
writes the files into a staging folder beside it (``.NAME.partial-PID``), flushes them to
disk, and puts the staged folder in the policy's place in one step: a rename where there is
no policy yet, else Linux's ``renameat2(RENAME_EXCHANGE)``, which swaps the two folders
atomically. Where the system has no exchange, the old folder is first renamed aside
(``.NAME.old-PID``) and put back by the next save should a kill fall between the two renames.
"""

from __future__ import annotations

import errno
import os
import shutil
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from gymfg_il.errors import ConfigError

# what a policy folder holds (``train bc``'s, and ``train ppo``'s curve and TensorBoard log)
POLICY_FILES = frozenset(
    {"config.json", "model.safetensors", "loss.png", "train_log.json"}
    | {"curve.json", "curve.png", "tensorboard"}
)
PARTIAL, OLD = "partial", "old"
AT_FDCWD, RENAME_EXCHANGE = -100, 2  # <fcntl.h>, <linux/fs.h>


def check_out(out: Path) -> None:
    """Refuse, before anything is trained, an ``out`` that is a file, whose folder cannot be
    written, or that holds files other than a policy's (replacing the folder would delete
    them)."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a folder for the policy")
    if out.is_dir():
        foreign = sorted(p.name for p in out.iterdir() if p.name not in POLICY_FILES)
        if foreign:
            shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
            raise ConfigError(
                f"--out {out} holds files that are not a policy's ({shown}); saving replaces "
                "the whole folder: give a new or empty folder, or a policy's folder"
            )
    probe = _beside(out, "write-check")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        probe.mkdir()
        probe.rmdir()
    except OSError as err:
        raise ConfigError(f"--out {out}: cannot write there ({err.strerror})") from None


@contextmanager
def staged(out: Path) -> Iterator[Path]:
    """A fresh staging folder to write the policy into; when the block ends without an
    error, the staging folder becomes ``out`` in one step (any older ``out`` is deleted), else
    it is removed and ``out`` stays as it was."""
    out = Path(out).absolute()
    _clear_leftovers(out)
    staging = _beside(out, f"{PARTIAL}-{os.getpid()}")
    if staging.exists():
        shutil.rmtree(staging)
    staging.mkdir(parents=True)
    try:
        yield staging
        _flush(staging)
        _swap_in(staging, out)
        _flush_folder(out.parent)
    finally:
        if staging.exists():  # the new files after an error, or the old policy after a swap
            shutil.rmtree(staging)


def _beside(out: Path, what: str) -> Path:
    return out.parent / f".{out.name}.{what}"


def _swap_in(staging: Path, out: Path) -> None:
    try:
        os.rename(staging, out)  # out absent, or an empty folder (which rename replaces)
        return
    except OSError as err:
        if err.errno not in (errno.EEXIST, errno.ENOTEMPTY):
            raise
    if _exchange(staging, out):
        return
    old = _beside(out, f"{OLD}-{os.getpid()}")
    os.rename(out, old)  # a kill here leaves out missing: the next save puts old back
    os.rename(staging, out)
    shutil.rmtree(old)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux ``renameat2`` with ``RENAME_EXCHANGE``); False
    where the system or the file system has no such call."""
    if sys.platform != "linux":
        return False
    import ctypes

    try:
        renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
    except AttributeError:  # a C library without it (glibc before 2.28)
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p]
    renameat2.argtypes += [ctypes.c_uint]
    if renameat2(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


def _flush(folder: Path) -> None:
    """The staged files on disk before the rename publishes them (else a power cut could
    leave the renamed folder with empty files)."""
    for path in folder.iterdir():
        if path.is_dir():  # a run's log folder (PPO's TensorBoard events)
            _flush(path)
            continue
        with open(path, "rb") as f:
            os.fsync(f.fileno())
    _flush_folder(folder)


def _flush_folder(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # systems that cannot open a folder (Windows) flush it with its files
        return
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _clear_leftovers(out: Path) -> None:
    """Remove what killed saves to ``out`` left: their staging folders, and put back an old
    policy that was renamed aside when the kill came before the new one took its place."""
    for path in sorted(out.parent.glob(f".{out.name}.*-*")):
        what, _, pid = path.name.removeprefix(f".{out.name}.").rpartition("-")
        if what not in (PARTIAL, OLD) or not pid.isdigit() or _alive(int(pid)):
            continue
        if what == OLD and not out.exists():
            os.rename(path, out)
        else:
            shutil.rmtree(path)


def _alive(pid: int) -> bool:
    if os.name != "posix":
        return True  # Windows' os.kill ends the process it is given: leave the folder
    if pid == os.getpid():
        return False  # our own leftover from an earlier save in this process
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's process
    return True
