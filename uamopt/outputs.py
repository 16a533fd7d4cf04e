"""Writing results: all-or-nothing output folders, one run per folder, and JSON helpers.

A command computes into a hidden staging folder beside ``--out`` (``.NAME.uamopt-stage-XXXXXXXX``
in its parent folder: the same file system, so a rename is atomic), flushes every file to disk,
and only then publishes:

- ``--out`` does not exist: the staging folder is renamed to ``--out`` in one ``rename``.
- ``--out`` is a folder: each file the command wrote replaces its namesake (``os.replace``,
  atomic per file) and each subfolder it wrote is merged the same way. Nothing else in ``--out``
  is touched or deleted; a user's folder where the command writes a file (or a file where it
  writes a folder) is refused before anything moves.

SIGINT and SIGTERM are held while publishing (uamopt.interrupts), so an interrupt leaves
``--out`` as it was or complete; only a hard kill (SIGKILL, power loss) while merging into an
existing folder can leave it with some files new and some old. A lock (``flock`` on
``.NAME.uamopt.lock`` beside ``--out``) held for the whole command stops a second run into the
same folder at once, and the run that holds it removes staging folders left by a killed run.
A full disk while staging ends with one error line; ``--out`` is untouched.

Test hook: ``UAMOPT_TEST_PAUSE_IN_MOVE=SECONDS`` sleeps inside the publish step (signals held),
after the first entry has moved, so a test can interrupt exactly there (tests/test_output_safety.py).
"""

from __future__ import annotations

import errno
import json
import math
import os
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from uamopt.errors import NoSpaceError, UamoptError
from uamopt.interrupts import deferred_signals

try:
    import fcntl
except ImportError:  # not POSIX (Windows): staging and the atomic move work, the lock does not
    fcntl = None

LOCK_SUFFIX = ".uamopt.lock"
STAGE_TAG = ".uamopt-stage-"
PAUSE_ENV = "UAMOPT_TEST_PAUSE_IN_MOVE"
NO_SPACE = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG}  # disk full, quota, file size limit


@dataclass(frozen=True)
class _Lock:
    fd: int
    path: Path
    site: Path  # the folder holding the lock file and the staging folders
    prefix: str  # ".NAME" beside --out, "" inside it


_held: dict[Path, _Lock] = {}  # real path of a locked output folder -> its lock (this process)
_published: set[Path] = set()  # output folders this process has published into


def _real(path: str | Path) -> Path:
    return Path(os.path.realpath(path))


def check_out_dir(out_dir: str | Path, option: str = "--out") -> Path:
    """Validate an output folder before any work is done (``option`` names it in errors)."""
    if not str(out_dir).strip():  # Path("") would be the current folder
        raise UamoptError("the output folder is an empty path", option, f"give a folder, e.g. {option} out/run")
    out = Path(out_dir)
    try:
        os.stat(out)
    except (FileNotFoundError, NotADirectoryError):
        pass  # a new folder (or a dangling symlink, whose target is made); a file in its path fails when made
    except OSError as exc:  # a symlink loop (ELOOP), a name too long: Path.exists() would say False and the move fail
        raise UamoptError(f"cannot use the output path {out}: {exc.strerror or exc}", option,
                          "give a folder path (resolve the symlinks in it)") from None
    if out.exists() and not out.is_dir():
        raise UamoptError(f"output path is a file: {out}", option, "give a folder path")
    real = _real(out)
    if real.parent == real:
        raise UamoptError(f"cannot write into the root folder {out}", option, "give a folder below it")
    return out


def published(out_dir: str | Path) -> bool:
    """True when this process has published results into ``out_dir`` (for the interrupt message)."""
    return _real(out_dir) in _published


def _cannot_write(exc: OSError, where: Path, option: str) -> UamoptError:
    return UamoptError(f"cannot write to {where}: {exc.strerror or exc}", option, "check the folder's path and permissions")


def _make_parents(folder: Path, option: str) -> list[Path]:
    """Create ``folder`` and its missing parents; returns those created (outermost first)."""
    missing = []
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    created = []
    try:
        for path in reversed(missing):
            path.mkdir()
            created.append(path)
    except OSError as exc:
        _remove_empty(created)
        raise _cannot_write(exc, path, option) from None
    return created


def _remove_empty(created: list[Path]) -> None:
    for path in reversed(created):
        try:
            path.rmdir()
        except OSError:
            return


def _acquire(lock_path: Path, out: Path, option: str) -> int:
    """flock ``lock_path`` without waiting. A holder removes its lock file when done, so the file
    locked must still be the one at ``lock_path``; else try again."""
    while True:
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise _cannot_write(exc, lock_path.parent, option) from None
        try:
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise UamoptError(f"another uamopt run is writing to {out}", option,
                              "wait for it to finish, or choose another folder") from None
        try:
            current = os.stat(lock_path)
        except FileNotFoundError:
            current = None
        if current is not None and os.path.samestat(os.fstat(fd), current):
            return fd
        os.close(fd)


def _remove_stale(site: Path, prefix: str) -> None:
    """Staging folders of a killed run into the same folder: no live run has one while we hold
    the lock, and the name is uamopt's own."""
    pattern = re.compile(re.escape(prefix + STAGE_TAG) + r"[A-Za-z0-9_]{8}")
    with suppress(OSError):  # a folder that cannot be listed: nothing to clear
        for path in site.iterdir():
            if pattern.fullmatch(path.name) and path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)


@contextmanager
def output_lock(out_dir: str | Path, option: str = "--out") -> Iterator[Path]:
    """Hold the lock on the output folder ``out_dir`` for the block; re-entrant in one process.

    Raises
    ------
    UamoptError
        Another run holds the lock, or the folder's parent cannot be created or written.
    """
    out = check_out_dir(out_dir, option)
    real = _real(out)
    if real in _held:
        yield out
        return
    created: list[Path] = []
    lock = None
    try:
        with deferred_signals():  # an interrupt here would leave the lock taken and not undone
            created = _make_parents(real.parent, option)
            # beside --out (same file system, nothing inside it until done); inside it when it exists
            # and its parent is read-only (``--out .`` in a folder whose parent is not the user's)
            inside = real.is_dir() and not os.access(real.parent, os.W_OK | os.X_OK)
            site, prefix = (real, "") if inside else (real.parent, "." + real.name)
            path = site / (prefix + LOCK_SUFFIX)
            lock = _held[real] = _Lock(_acquire(path, out, option), path, site, prefix)
        _remove_stale(lock.site, lock.prefix)
        yield out
    finally:
        with deferred_signals():
            if lock is not None:
                del _held[real]
                lock.path.unlink(missing_ok=True)  # before unlocking: see _acquire
                os.close(lock.fd)
            _remove_empty(created)  # only the parents this run created, and only if still empty


def _sync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _sync_tree(folder: Path) -> None:
    """Flush every file and folder under ``folder`` to disk (before any rename makes them visible)."""
    for root, _, files in os.walk(folder):
        for name in files:
            if not os.path.islink(os.path.join(root, name)):
                _sync(Path(root) / name)
        _sync(Path(root))


def _pause_for_tests() -> None:
    try:
        seconds = float(os.environ.get(PAUSE_ENV, "0"))
    except ValueError:
        return
    if seconds > 0:
        sys.stderr.write(f"{PAUSE_ENV}: pausing {seconds:g} s inside the move\n")
        sys.stderr.flush()
        time.sleep(seconds)


def _clashes(stage: Path, out: Path, option: str) -> None:
    """Refuse, before anything moves, where a file and a folder would take each other's place."""
    for entry in stage.iterdir():
        target = out / entry.name
        if not os.path.lexists(target):
            continue
        if entry.is_dir():
            if target.is_symlink() or not target.is_dir():
                raise UamoptError(f"{target} is in the way of the folder {entry.name} that the command writes", option,
                                  "move it away or choose another folder; nothing was written")
            _clashes(entry, target, option)
        elif target.is_dir() and not target.is_symlink():
            raise UamoptError(f"the folder {target} is in the way of the file {entry.name} that the command writes",
                              option, "move it away or choose another folder; nothing was written")


def _merge(stage: Path, out: Path, pause: bool) -> None:
    """Move every entry of ``stage`` into the existing folder ``out`` (after :func:`_clashes`)."""
    for entry in sorted(stage.iterdir()):
        target = out / entry.name
        if entry.is_dir() and os.path.lexists(target):
            _merge(entry, target, pause=False)
        else:
            os.replace(entry, target)
        if pause:
            _pause_for_tests()
            pause = False
    _sync(out)


def _publish(stage: Path, real: Path, option: str) -> None:
    if real.exists():
        _clashes(stage, real, option)
    with deferred_signals():
        if real.exists():
            _merge(stage, real, pause=True)
        else:
            _pause_for_tests()
            os.rename(stage, real)
            _sync(real.parent)
        _published.add(real)


@contextmanager
def staged_output(out_dir: str | Path, option: str = "--out") -> Iterator[Path]:
    """Yield a staging folder; when the block ends without error, publish its content into
    ``out_dir`` (module docstring), else discard it. Holds the folder's lock throughout.

    Raises
    ------
    UamoptError
        Another run holds the lock; the disk is full; a file and a folder clash in ``out_dir``.
    """
    with output_lock(out_dir, option) as out:
        real, lock = _real(out), _held[_real(out)]
        stage: Path | None = None
        staged = False
        try:
            try:
                with deferred_signals():  # an interrupt arriving now is raised once ``stage`` is known
                    stage = Path(tempfile.mkdtemp(prefix=lock.prefix + STAGE_TAG, dir=lock.site))
            except OSError as exc:
                raise _cannot_write(exc, lock.site, option) from None
            umask = os.umask(0)
            os.umask(umask)
            stage.chmod(0o777 & ~umask)  # it may become --out itself: a folder as mkdir makes it, not mkdtemp's 0700
            yield stage
            _sync_tree(stage)
            staged = True
            _publish(stage, real, option)
        except OSError as exc:
            if exc.errno not in NO_SPACE:
                raise
            state = "nothing was written to it" if not staged else "it may hold some of the new files"
            raise NoSpaceError(f"cannot write the results: {exc.strerror}", str(out),
                              f"free some space or choose a folder on another disk; {state}") from None
        finally:  # an interrupt between mkdtemp and the block left the staging folder behind
            if stage is not None:
                with deferred_signals():
                    shutil.rmtree(stage, ignore_errors=True)


def _jsonable(value: Any) -> Any:
    # numpy as already imported, if it is: this module imports none, so that the line after an
    # interrupt (uamopt.cli._interrupted asks `published`) never imports it again; a signal inside
    # numpy's own import leaves it unloadable ("cannot load module more than once per process")
    np = sys.modules.get("numpy")
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if np is not None and isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if np is not None and isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def write_json(path: str | Path, data: Any) -> None:
    """Write ``data`` as indented JSON (numpy values converted, NaN/inf as null)."""
    Path(path).write_text(json.dumps(_jsonable(data), indent=2, ensure_ascii=False) + "\n", encoding="utf-8")


def size_text(n: float) -> str:
    """A size in bytes as ``812 B``, ``16.2 KB``, ``3.1 MB``, ``1.5 GB`` (powers of 1024)."""
    for unit in ("B", "KB", "MB", "GB"):
        if n < 1024 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    raise AssertionError  # unreachable


def out_of_space(exc: OSError, path: Path, size: int, need: int | None = None, where: str = "", keep: str = "",
                 exact: bool = True) -> NoSpaceError:
    """The one-line error of a write to ``path`` (``size`` bytes; ``exact`` False: the bytes
    written when it stopped) that a full disk, a quota or a file-size limit stopped; ``need``: the
    bytes still to write, this file included; ``keep``: what the user keeps (the end of the fix)."""
    where = where or str(path.parent)
    keep = keep or f"then run the command again ({path.name} was not written)"
    if exc.errno == errno.EFBIG:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
        limit = (f"more than the file size limit of {size_text(soft)} (ulimit -f)" if soft != resource.RLIM_INFINITY
                 else "more than the file system's largest file")
        return NoSpaceError(f"cannot write {path}: File too large: it needs {'' if exact else 'more than '}{size_text(size)}, "
                           f"{limit}", where,
                           f"raise the limit (ulimit -f) or write to another disk, {keep}")
    try:
        free = f"{size_text(shutil.disk_usage(path.parent).free)} free"
    except OSError:
        free = "free space unknown"
    need = max(need or 0, size)
    amount = f"about {size_text(need)}" if exact or need > size else f"more than {size_text(size)}"
    return NoSpaceError(f"cannot write {path}: {exc.strerror or 'No space left on device'}: needs {amount} to finish, {free}",
                       where,
                       f"free some space or write to another disk, {keep}")


def atomic_write(path: Path, write, need: int | None = None, where: str = "", keep: str = "") -> None:
    """Write ``write`` (bytes, or a callable ``write(tmp_path)``) to a temporary file beside
    ``path``, flush it to disk and rename it over ``path``.

    Raises
    ------
    UamoptError
        The disk is full or the file too large (:func:`out_of_space`; ``need``, ``where`` and
        ``keep`` go into its message); the temporary file is removed and ``path`` is as it was.
    """
    data = bytes(write) if isinstance(write, (bytes, bytearray, memoryview)) else None
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 would make results private
        if data is not None:
            with open(tmp, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        else:
            write(Path(tmp))
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        size = len(data) if data is not None else file_size(tmp)
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        if exc.errno in NO_SPACE:
            raise out_of_space(exc, path, size, need, where, keep, exact=data is not None) from None
        raise
    except BaseException:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        raise
    try:  # make the rename itself durable
        dfd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
    except OSError:
        pass


def file_size(path) -> int:
    """The size of the file at ``path`` in bytes; 0 when there is none (or ``path`` is None)."""
    try:
        return os.stat(path).st_size if path is not None else 0
    except OSError:
        return 0
