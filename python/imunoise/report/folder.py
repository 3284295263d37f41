"""The report's folder: which folders are reports, and what an earlier report left.

A report folder holds :data:`MANIFEST`, the list of the files the last report wrote
there. :func:`claim` refuses to write into an existing folder that holds other
things and no manifest unless ``force`` is given (the report would mix its files
with someone else's); :func:`settle` removes what the previous report wrote and
this one did not (figures of sections that no longer apply) and records the new
list. Every file is written atomically (:mod:`imunoise._support.atomic`), so an
interrupted report leaves each file either old or new, never partial, and the
manifest still names the folder a report: :func:`mark` writes it before the first
file. A report that fails or is interrupted takes back what it added
(:class:`Undo`): a new folder goes entirely, an existing one loses only the files
this report created.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterable
from pathlib import Path

from imunoise._support import atomic as _atomic
from imunoise.errors import ImunoiseValueError

__all__ = ["MANIFEST", "Undo", "claim", "mark", "settle"]

#: The file that marks a folder as an imunoise report and lists its files.
MANIFEST = "imunoise-report.json"
_VERSION = 1
#: The files every report writes besides its figures.
FIXED = ("report.md", "report.html", "noise.json", "imu.yaml", "ekf_bias_model.yaml")


def _listed(out: Path) -> list[str]:
    """The relative paths the manifest lists (only plain paths inside ``out``)."""
    try:
        data = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
        files = data["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return []
    keep = []
    for name in files if isinstance(files, list) else []:
        if not isinstance(name, str) or not name or os.path.isabs(name):
            continue
        parts = Path(name).parts
        if ".." in parts:
            continue
        keep.append(Path(*parts).as_posix())
    return keep


def _write(out: Path, files: Iterable[str]) -> None:
    text = json.dumps({"imunoise_report": _VERSION, "files": sorted(set(files))}, indent=1)
    _atomic.write_text(out / MANIFEST, text + "\n")


def claim(out, *, force: bool = False, inputs: Iterable = ()) -> list[str]:
    """Check that a report may be written into ``out`` (nothing is created); returns
    the files the previous report there listed.

    Raises ``ValueError`` when ``out`` is a file, or an existing non-empty folder
    without :data:`MANIFEST` and ``force`` is False, or when an input log is one
    of the files the report would replace.
    """
    out = Path(os.fspath(out))
    if out.exists() and not out.is_dir():
        raise ImunoiseValueError(f"report output {str(out)!r} exists and is not a folder")
    previous: list[str] = []
    if out.is_dir():
        if (out / MANIFEST).is_file():
            previous = _listed(out)
        elif any(out.iterdir()) and not force:
            raise ImunoiseValueError(
                f"report output {str(out)!r} is an existing folder that holds other files "
                f"and no {MANIFEST} (it is not a report): choose a new folder, or pass "
                f"--force (force=True) to write the report into it"
            )
    for name in {*previous, *FIXED}:
        _atomic.refuse_input(out / name, inputs)
    return previous


def mark(out, previous: Iterable[str]) -> None:
    """Create ``out`` and its manifest (still listing ``previous``) before the first
    file is written: an interrupted report leaves a folder known to be a report."""
    out = Path(os.fspath(out))
    out.mkdir(parents=True, exist_ok=True)
    _write(out, previous)


def settle(out, written: Iterable, previous: Iterable[str], *, inputs: Iterable = ()) -> None:
    """Remove the files of the previous report that this one did not write, and
    list ``written`` (paths under ``out``) in the manifest."""
    out = Path(os.fspath(out))
    new = {Path(p).relative_to(out).as_posix() for p in written}
    for name in set(previous) - new:
        path = out / name
        try:
            _atomic.refuse_input(path, inputs)
        except ValueError:
            continue  # never remove an input log
        if path.is_file() or path.is_symlink():
            path.unlink(missing_ok=True)
    _write(out, new)


class Undo:
    """Removes what a report into ``out`` added, should it fail or be interrupted:
    the folders it created (``out`` and any missing parent), or in a folder that
    existed the entries of ``out`` and ``out/figures`` that were not there before
    (files replaced by this report stay new, as each file is old or new). Made
    before the report writes anything; calling it twice is harmless."""

    def __init__(self, out) -> None:
        self.out = Path(os.path.abspath(os.fspath(out)))
        top, p = None, self.out
        while not p.exists() and p != p.parent:
            top, p = p, p.parent
        self.top = top
        self.before = set() if top is not None else _entries(self.out)

    def __call__(self) -> None:
        if self.top is not None:
            shutil.rmtree(self.top, ignore_errors=True)
            return
        # the deepest first: a new figures/ goes after the files in it
        for path in sorted(_entries(self.out) - self.before, key=lambda p: -len(p.parts)):
            try:
                if path.is_dir() and not path.is_symlink():
                    shutil.rmtree(path, ignore_errors=True)
                else:
                    path.unlink(missing_ok=True)
            except OSError:
                pass  # the folder is the user's: leave what cannot be removed


def _entries(out: Path) -> set[Path]:
    """The entries of ``out`` and of ``out/figures`` (where a report writes)."""
    found: set[Path] = set()
    for d in (out, out / "figures"):
        try:
            found.update(d.iterdir())
        except OSError:
            continue
    return found
