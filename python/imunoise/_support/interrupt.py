"""Ctrl-C on the command line: exit 130 and one line, within a second, at any moment.

The ``imunoise`` process (the console script, or ``python -m imunoise.cli``) spends
its first ~0.8 s importing numpy, scipy and the core. Python's own handler would
turn a Ctrl-C there into a KeyboardInterrupt traceback from inside some import and
a death by SIGINT, so :func:`guard_startup`, the first thing ``import imunoise``
runs, ends such a process at once (nothing has been written yet). A library user's
process keeps Python's handler: the guard acts only in the command's own process.

Once the command runs (:func:`work`), Ctrl-C is Python's KeyboardInterrupt again:
it unwinds, so the temporaries of files being written are removed, and the Rust
core's loops stop within milliseconds. A kernel that does not look at the flag
would hold the unwinding up for as long as it runs; a watchdog thread, woken by the
signal itself (``signal.set_wakeup_fd``: written by the C-level handler whatever
the main thread is doing), ends the process :data:`DEADLINE` seconds after the
signal if it is still there, after running the clean-ups registered with
:func:`undo_on_exit`. A second Ctrl-C ends it at once. A KeyboardInterrupt that
lands in a weakref callback or a finaliser, where Python prints "Exception ignored"
and carries on, is raised again in the main thread instead.
"""

from __future__ import annotations

import _thread
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["DEADLINE", "at_hard_exit", "done", "guard_startup", "interrupted", "undo_on_exit",
           "work"]

#: Seconds from a Ctrl-C (or SIGTERM) to the process's end at the latest.
DEADLINE = 0.6

#: Console script names and ``-m`` modules that are the command line.
_SCRIPTS = ("imunoise", "imunoise.exe", "imunoise-script.py")
_MODULES = ("imunoise.cli",)

_state = {"guarded": False, "said": False, "backstop": True, "again": 0, "stopping": False}
_cleanups: list[Callable[[], None]] = []


def _is_command_line() -> bool:
    """True in the ``imunoise`` command's own process."""
    if sys.argv and os.path.basename(sys.argv[0] or "") in _SCRIPTS:
        return True
    orig = list(getattr(sys, "orig_argv", ()))
    return any(a == "-m" and b in _MODULES for a, b in zip(orig, orig[1:], strict=False)) or \
        any(a in (f"-m{m}" for m in _MODULES) for a in orig)


_said = threading.RLock()


def _say(signum: int) -> None:
    # once, though the main thread and the watchdog may both get here: written under
    # the lock, so the other cannot end the process between the flag and the line
    with _said:
        if _state["said"]:
            return
        word = "interrupted" if signum == signal.SIGINT else "terminated"
        os.write(2, f"imunoise: {word}\n".encode())
        _state["said"] = True


def _end(signum: int) -> None:
    """Ends the process now: the clean-ups, the one line, exit 128 + signum."""
    for fn in list(_cleanups):
        try:
            fn()
        except Exception:  # noqa: BLE001 - the process ends either way
            pass
    _say(signum)
    os._exit(128 + signum)


def _at_once(signum, frame) -> None:
    # start-up and the tail after the command: nothing is being written; a second
    # Ctrl-C must not run this again halfway through the first
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _end(signum)


def guard_startup() -> None:
    """In the command's process (main thread, Python's handler still in place): Ctrl-C
    ends it at once until :func:`work`, and the watchdog listens for signals."""
    if (_state["guarded"] or threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
            or not _is_command_line()):
        return
    read, write = os.pipe()
    try:
        os.set_blocking(write, False)  # the C handler must never block on a full pipe
        signal.set_wakeup_fd(write, warn_on_full_buffer=False)
    except (AttributeError, OSError, ValueError):  # pragma: no cover - Windows pipes
        os.close(read)
        os.close(write)
        return
    signal.signal(signal.SIGINT, _at_once)
    _state["guarded"] = True
    previous = sys.unraisablehook

    def _unraisable(info) -> None:
        # a Ctrl-C that Python would print as "Exception ignored" and then lose
        if info.exc_type is not None and issubclass(info.exc_type, KeyboardInterrupt):
            _state["again"] += 1
            _thread.interrupt_main()
            return
        previous(info)

    sys.unraisablehook = _unraisable
    threading.Thread(target=_watch, args=(read,), name="imunoise-interrupt",
                     daemon=True).start()


def _watch(fd: int) -> None:
    """The watchdog: the first SIGINT or SIGTERM gives the process DEADLINE seconds;
    a second ends it at once."""
    first = threading.Event()
    while True:
        try:
            data = os.read(fd, 64)
        except OSError:  # pragma: no cover
            return
        if not data:  # pragma: no cover
            return
        for signum in data:
            if signum not in (signal.SIGINT, signal.SIGTERM) or not _state["backstop"]:
                continue
            if _state["again"] and signum == signal.SIGINT:  # _unraisable's, not a user's
                _state["again"] -= 1
                continue
            if first.is_set():
                _end(signum)
            first.set()
            threading.Thread(target=_deadline, args=(signum,), daemon=True).start()


def _deadline(signum: int) -> None:
    threading.Event().wait(DEADLINE)
    _end(signum)


def work(*, backstop: bool = True) -> None:
    """The command starts: Ctrl-C raises KeyboardInterrupt. ``backstop`` False for a
    command whose own clean-up may take longer than DEADLINE and must finish (the
    recorder writes the sensor's settings back)."""
    _state["backstop"] = backstop
    if _state["guarded"]:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def done(*, interrupted: bool = False) -> None:
    """The command has returned: Ctrl-C ends the process at once again. After an
    interrupt (``interrupted``) further ones are ignored instead: the watchdog ends
    the process within DEADLINE anyway, and an ignored SIGINT stays ignored through
    the interpreter's exit, where Python puts back the default action and a second
    Ctrl-C would be a death by SIGINT (-2) instead of exit 130."""
    if not _state["guarded"]:
        return
    _state["stopping"] = _state["stopping"] or interrupted
    signal.signal(signal.SIGINT, signal.SIG_IGN if _state["stopping"] else _at_once)


def interrupted(signum: int = signal.SIGINT) -> None:
    """Print the one line of an interrupted command (once per process)."""
    if _state["guarded"]:
        _say(signum)
    else:
        word = "interrupted" if signum == signal.SIGINT else "terminated"
        print(f"imunoise: {word}", file=sys.stderr)


def at_hard_exit(fn: Callable[[], None]) -> None:
    """Run ``fn`` should the watchdog end the process (atexit does not run then)."""
    _cleanups.append(fn)


@contextmanager
def undo_on_exit(fn: Callable[[], None]) -> Iterator[None]:
    """Run ``fn`` (e.g. remove a folder being built) should the watchdog end the
    process while the block runs; normal unwinding is the block's own business."""
    _cleanups.append(fn)
    try:
        yield
    finally:
        _cleanups.remove(fn)


# Armed on import: ``import imunoise`` imports this module before anything heavy.
guard_startup()
