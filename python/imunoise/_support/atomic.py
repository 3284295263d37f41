"""Every file imunoise writes goes through this module.

A target is never written in place: the bytes go to a temporary beside it with a
unique name (``.<name>.<pid>-<random>.imunoise-tmp<suffix>``, so two writers of
one target never share it), are flushed to disk (``fsync``) and then renamed onto
the target, which therefore holds either its old content or the complete new one.
An exception (Ctrl-C included) removes the temporary. A process killed outright
(``kill -9``) cannot clean up: the next write into the same directory removes the
temporaries of processes that no longer run and warns about them.

A replaced file keeps its permission bits; a new file gets the umask's (as
``open`` would give it). An output that is one of the inputs is refused.

A data file and its metadata file (:func:`publish_pair`) cannot be renamed in one
step, so the metadata carries the data's :func:`fingerprint` (bytes, modification
time, BLAKE3 digest) and readers refuse metadata whose fingerprint is not the file's: a
kill between the two renames leaves the new data beside the old metadata, which
no reader takes for a pair. The two renames are made holding a lock on the
directory, so two writers of one output publish their pairs one after the other,
never interleaved.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import hashlib
import os
import re
import secrets
import shutil
import sys
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import BinaryIO

from imunoise._core import digest as _core_digest
from imunoise._support import interrupt as _interrupt
from imunoise.errors import DataWarning, ImunoiseValueError

__all__ = [
    "TEMP_TAG",
    "exchange_dir",
    "fingerprint",
    "hashed_fingerprint",
    "publish_pair",
    "refuse_input",
    "remove_stale",
    "same_content",
    "synced_fingerprint",
    "publish",
    "replacing",
    "staged",
    "sync",
    "temporary_beside",
    "write_bytes",
    "write_text",
]

#: The mark in the name of every temporary imunoise writes.
TEMP_TAG = ".imunoise-tmp"
_TEMP_NAME = re.compile(r"^\..+\.(\d+)-[0-9a-f]{8}" + re.escape(TEMP_TAG) + r"(\.[^.]+)?$")
_cleaned: set[str] = set()  # directories already swept by this process


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def remove_stale(directory) -> list[Path]:
    """Remove the temporaries left in ``directory`` by imunoise processes that were
    killed before they could (their process no longer runs); warns when there were
    any. Returns what was removed."""
    directory = Path(directory)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    for entry in entries:
        m = _TEMP_NAME.match(entry.name)
        if m is None or _alive(int(m.group(1))):
            continue
        path = Path(entry.path)
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
        except FileNotFoundError:
            continue
        except OSError:
            continue
        removed.append(path)
    if removed:
        names = ", ".join(p.name for p in removed[:3]) + (" ..." if len(removed) > 3 else "")
        warnings.warn(
            f"removed {len(removed)} temporary file(s) left in {str(directory)!r} by an "
            f"interrupted imunoise run: {names}",
            DataWarning,
            stacklevel=3,
        )
    return removed


def _sweep_once(directory: Path) -> None:
    key = os.path.abspath(directory)
    if key not in _cleaned:
        _cleaned.add(key)
        remove_stale(directory)


def temporary_beside(target) -> Path:
    """A fresh unique temporary name in ``target``'s directory (nothing is created);
    stale temporaries of killed runs in that directory are removed first."""
    target = Path(os.fspath(target))
    directory = target.parent
    _sweep_once(directory)
    name = f".{target.name}.{os.getpid()}-{secrets.token_hex(4)}{TEMP_TAG}{target.suffix}"
    return directory / name


def refuse_input(target, inputs: Iterable) -> None:
    """Raise ``ValueError`` when ``target`` is one of ``inputs`` (the same file,
    whatever the path says: links and ``..`` included)."""
    target = os.fspath(target)
    if not os.path.exists(target):
        return
    for source in inputs:
        if source is None or not isinstance(source, str | os.PathLike):
            continue
        source = os.fspath(source)
        try:
            same = os.path.samefile(target, source)
        except OSError:
            continue
        if same:
            raise ImunoiseValueError(
                f"output {target!r} is the input {source!r}: writing it would destroy the "
                f"input; choose another output"
            )


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:  # pragma: no cover - e.g. Windows: directories cannot be opened
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover - some file systems refuse fsync of a directory
        pass
    finally:
        os.close(fd)


def _keep_mode(tmp: Path, target: Path) -> None:
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        return
    os.chmod(tmp, mode & 0o7777)


def sync(path) -> None:
    """Flush the file at ``path`` (or, for a directory, every file in it and the
    directory itself) to disk."""
    path = Path(path)
    if path.is_dir():
        for child in path.iterdir():
            if child.is_file():
                sync(child)
        _fsync_dir(path)
        return
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def publish(tmp, target) -> Path:
    """Flush the finished temporary file ``tmp`` to disk, give it the mode of the
    file it replaces, and rename it onto ``target``."""
    tmp, target = Path(tmp), Path(target)
    sync(tmp)
    _keep_mode(tmp, target)
    os.replace(tmp, target)
    _fsync_dir(target.parent)
    return target


def _discard(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink()


@contextlib.contextmanager
def replacing(target, *, inputs: Iterable = ()) -> Iterator[BinaryIO]:
    """Open a binary file to write ``target``'s new content into.

    On a normal exit the content is flushed, fsync-ed and renamed onto ``target``;
    on an exception (``KeyboardInterrupt`` included) the temporary is removed and
    ``target`` is left as it was. ``inputs`` are refused as the target.
    """
    target = Path(os.fspath(target))
    with staged(target, inputs=inputs) as (fh, tmp):
        yield fh
    try:
        _keep_mode(tmp, target)
        os.replace(tmp, target)
    except BaseException:
        _discard(tmp)
        raise
    _fsync_dir(target.parent)


@contextlib.contextmanager
def staged(target, *, inputs: Iterable = ()) -> Iterator[tuple[BinaryIO, Path]]:
    """Like :func:`replacing`, but the finished temporary (flushed, fsync-ed) is left
    for the caller to :func:`publish_pair`: yields ``(file, temporary)``. On an
    exception the temporary is removed."""
    target = Path(os.fspath(target))
    refuse_input(target, inputs)
    tmp = temporary_beside(target)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    # Ctrl-C's watchdog may end the process before the unwinding reaches the except
    # below (a long fsync): it removes the temporary then.
    with _interrupt.undo_on_exit(lambda: _discard(tmp)):
        try:
            with os.fdopen(fd, "wb") as fh:
                yield fh, tmp
                fh.flush()
                os.fsync(fh.fileno())
        except BaseException:
            _discard(tmp)
            raise


#: Bytes hashed at a time by :func:`_sha256` (bounds the memory it needs).
_HASH_BLOCK = 1 << 22


def fingerprint(path) -> dict:
    """What identifies the content of the file at ``path``: ``{"bytes", "mtime_ns",
    "blake3"}`` (JSON-able; the digest is hashed by the core on every thread). A
    rename keeps all three; a copy keeps bytes and digest."""
    size, mtime_ns, digest = _core_digest.fingerprint(path)
    return {"bytes": size, "mtime_ns": mtime_ns, "blake3": digest}


def hashed_fingerprint(path, blake3: str) -> dict:
    """:func:`fingerprint` of the file at ``path`` whose BLAKE3 digest ``blake3`` its
    writer computed from the bytes it wrote (the data is not read again); size and
    time are the file's now."""
    st = os.stat(path)
    return {"bytes": st.st_size, "mtime_ns": st.st_mtime_ns, "blake3": blake3}


def _sha256(path) -> str:
    """The SHA-256 of the file at ``path`` (the digest earlier versions wrote)."""
    digest = hashlib.sha256()
    block = bytearray(_HASH_BLOCK)  # one buffer read into: fresh bytes per read page-fault
    with open(path, "rb") as f, memoryview(block) as view:
        while got := f.readinto(block):
            digest.update(view[:got])
    return digest.hexdigest()


def synced_fingerprint(path) -> dict:
    """:func:`sync` the file at ``path`` and return its :func:`fingerprint`; the flush
    to disk runs in a thread while the hash reads the page cache (neither changes
    the file, so the order does not matter)."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1, thread_name_prefix="imunoise-sync") as pool:
        flushed = pool.submit(sync, path)
        mark = fingerprint(path)
        flushed.result()
    return mark


def same_content(path, mark: dict) -> bool:
    """True when the file at ``path`` is the one :func:`fingerprint` described as
    ``mark``: same size, and the same modification time (the fast path: the file
    was not rewritten since) or, after a copy, the same digest: ``mark``'s
    ``"blake3"``, or the ``"sha256"`` that earlier versions wrote instead."""
    st = os.stat(path)
    if st.st_size != mark["bytes"]:
        return False
    if st.st_mtime_ns == mark["mtime_ns"]:
        return True
    if "blake3" in mark:
        return fingerprint(path)["blake3"] == mark["blake3"]
    return _sha256(path) == mark["sha256"]


@contextlib.contextmanager
def _directory_lock(directory: Path) -> Iterator[None]:
    """An exclusive advisory lock on ``directory`` (``flock``), where the system has one."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: no flock
        yield
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def publish_pair(tmp, target, meta_of, meta_target, *, mark: dict | None = None
                 ) -> tuple[Path, Path]:
    """Publish the finished temporary ``tmp`` as ``target`` with its metadata.

    ``meta_of(fingerprint)`` gives the metadata's text, which must carry the
    fingerprint of the data (see the module docstring): ``mark`` when its writer
    hashed it (:func:`hashed_fingerprint`), else :func:`synced_fingerprint`'s. The
    metadata is written to its own temporary first, then both are renamed, data
    first, holding the directory's lock. On an exception both temporaries are
    removed."""
    tmp, target, meta_target = Path(tmp), Path(target), Path(meta_target)
    temporaries = [tmp]

    def discard() -> None:
        for path in temporaries:
            _discard(path)

    # Ctrl-C's watchdog may end the process before the unwinding reaches the except
    # below (the fsync beside the hash can be slow): it removes the temporaries then.
    with _interrupt.undo_on_exit(discard):
        try:
            if mark is None:
                mark = synced_fingerprint(tmp)
            else:
                sync(tmp)
            _keep_mode(tmp, target)
            text = meta_of(mark)
            meta_tmp = temporary_beside(meta_target)
            temporaries.append(meta_tmp)
            with open(meta_tmp, "xb") as fh:
                fh.write(text.encode("utf-8"))
                fh.flush()
                os.fsync(fh.fileno())
            _keep_mode(meta_tmp, meta_target)
            with _directory_lock(target.parent):
                os.replace(tmp, target)
                os.replace(meta_tmp, meta_target)
        except BaseException:
            discard()
            raise
    _fsync_dir(target.parent)
    return target, meta_target


def write_bytes(target, data: bytes, *, inputs: Iterable = ()) -> Path:
    """Write ``data`` to ``target`` atomically; returns ``target`` as a Path."""
    with replacing(target, inputs=inputs) as fh:
        fh.write(data)
    return Path(os.fspath(target))


def write_text(target, text: str, *, inputs: Iterable = ()) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``target`` atomically."""
    return write_bytes(target, text.encode("utf-8"), inputs=inputs)


_RENAME_EXCHANGE = 2


def exchange_dir(staging, target) -> bool:
    """Swap the directories ``staging`` and ``target`` in one step (Linux
    ``renameat2(RENAME_EXCHANGE)``); False where the system cannot."""
    if not sys.platform.startswith("linux"):  # pragma: no cover
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):  # pragma: no cover - old C library
        return False
    at_fdcwd = -100
    rc = renameat2(at_fdcwd, os.fsencode(staging), at_fdcwd, os.fsencode(target),
                   _RENAME_EXCHANGE)
    if rc == 0:
        _fsync_dir(Path(os.fspath(target)).parent)
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EXDEV):  # pragma: no cover
        return False
    raise OSError(err, os.strerror(err), os.fspath(target))  # pragma: no cover
