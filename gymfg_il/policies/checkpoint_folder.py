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

Replacing the folder deletes what it held, so ``check_out`` lets a save replace only what a
save wrote, by kind and content as well as name: a folder named ``loss.png`` or a
``tensorboard/`` holding a user's notes is the user's, and refused.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import stat
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from gymfg_il.errors import ConfigError

# what a policy folder holds: ``train bc``'s files, ``train ppo``'s curve, and folders of
# what ``train ppo`` writes (its TensorBoard log, and with --checkpoints each evaluated actor
# as a policy, ``checkpoints/step-N`` and ``checkpoints/average``: ``rl.judge``); each is
# checked by kind and content (``foreign_files``)
POLICY_FILES = frozenset(
    {"config.json", "model.safetensors", "loss.png", "train_log.json", "curve.json", "curve.png"}
)
CHECKPOINT = re.compile(r"step-\d+|average")  # the names of the actors in checkpoints/
CHECKPOINT_FILES = frozenset({"config.json", "model.safetensors"})  # what ``save_policy`` writes
EVENTS = "events.out.tfevents."  # how torch's SummaryWriter names TensorBoard event files
PARTIAL, OLD = "partial", "old"
AT_FDCWD, RENAME_EXCHANGE = -100, 2  # <fcntl.h>, <linux/fs.h>
SHOWN = 5  # foreign files named in the error


def check_out(out: Path) -> None:
    """Refuse, before anything is trained, an ``out`` that is a file, whose folder cannot be
    written, or that holds anything a policy's save did not write (``foreign_files``:
    replacing the folder would delete it)."""
    out = Path(out)
    if out.is_symlink():  # saving swaps the folder in whole: the link would go, not its target
        raise ConfigError(
            f"--out {out} is a link (to {os.readlink(out)}); saving replaces the folder whole, "
            f"which would replace the link: give the folder itself (--out {out.resolve()})"
        )
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a folder for the policy")
    if out.is_dir():
        foreign = foreign_files(out)
        if foreign:
            shown = "; ".join(foreign[:SHOWN]) + ("; ..." if len(foreign) > SHOWN else "")
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


def foreign_files(folder: Path) -> list[str]:
    """What in the policy folder ``folder`` a save did not write, one entry each (its path
    in the folder, and why where the name is a policy's): a policy's file names must be
    regular files (no folder, link or FIFO), ``tensorboard/`` must hold TensorBoard event
    files only, ``checkpoints/`` only the policies ``train ppo --checkpoints`` saved."""
    found = []
    for path in sorted(folder.iterdir()):
        if path.name in POLICY_FILES:
            found += [] if _regular(path) else [f"{path.name}: {_kind(path)}, not a file"]
        elif path.name == "tensorboard":
            found += _foreign_events(path, "tensorboard")
        elif path.name == "checkpoints":
            found += _foreign_checkpoints(path)
        else:
            found.append(path.name)
    return found


def _foreign_checkpoints(path: Path) -> list[str]:
    """What in ``checkpoints/`` is not an evaluated actor ``train ppo --checkpoints`` saved:
    a folder ``step-N`` or ``average`` holding a policy's config.json and weights alone."""
    if not _folder(path):
        return [f"checkpoints: {_kind(path)}, not the folder train ppo --checkpoints writes"]
    found = []
    for actor in sorted(path.iterdir()):
        where = f"checkpoints/{actor.name}"
        if not (_folder(actor) and CHECKPOINT.fullmatch(actor.name)):
            found.append(f"{where}: not a step-N or average policy folder")
            continue
        for part in sorted(actor.iterdir()):
            if part.name not in CHECKPOINT_FILES:
                found.append(f"{where}/{part.name}: not a policy's file")
            elif not _regular(part):
                found.append(f"{where}/{part.name}: {_kind(part)}, not a file")
    return found


def _foreign_events(path: Path, where: str) -> list[str]:
    """What in the TensorBoard log folder ``path`` (``where`` in the policy folder) is not
    a folder of event files (stable-baselines3 writes ``ppo_N/events.out.tfevents.*``)."""
    if not _folder(path):
        return [f"{where}: {_kind(path)}, not a TensorBoard log folder"]
    found = []
    for part in sorted(path.iterdir()):
        inside = f"{where}/{part.name}"
        if _folder(part):
            found += _foreign_events(part, inside)
        elif not (_regular(part) and part.name.startswith(EVENTS)):
            found.append(f"{inside}: not a TensorBoard event file")
    return found


def _regular(path: Path) -> bool:
    return stat.S_ISREG(path.lstat().st_mode)


def _folder(path: Path) -> bool:
    return stat.S_ISDIR(path.lstat().st_mode)


def _kind(path: Path) -> str:
    mode = path.lstat().st_mode
    kinds = {stat.S_ISDIR: "a folder", stat.S_ISLNK: "a link", stat.S_ISFIFO: "a FIFO"}
    return next((what for test, what in kinds.items() if test(mode)), "a special file")


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
