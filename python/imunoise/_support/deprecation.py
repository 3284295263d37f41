"""Keep old call forms of the public API working for one release, with a warning.

:func:`old_call_forms` wraps a function whose options became keyword-only or
whose keywords got a new name; ``inspect.signature`` of the wrapper shows the
new signature.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Mapping, Sequence
from typing import TypeVar

from imunoise._support import warn as _warn
from imunoise.errors import ImunoiseDeprecationWarning, ImunoiseTypeError

F = TypeVar("F", bound=Callable)


def old_call_forms(
    *, keyword_only: Sequence[str] = (), renamed: Mapping[str, str] | None = None
) -> Callable[[F], F]:
    """Accept the calls a function took before, with a ``DeprecationWarning``.

    Parameters
    ----------
    keyword_only : sequence of str
        Options that became keyword-only, in their old positional order:
        ``f(x, 15)`` of a new ``f(x, *, bins)`` is called as ``f(x, bins=15)``.
    renamed : mapping, optional
        Old keyword -> new keyword: ``{"n": "n_samples"}`` maps ``f(n=5)``.
    """
    renamed = dict(renamed or {})

    def decorate(func: F) -> F:
        params = inspect.signature(func).parameters.values()
        n_positional = sum(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) for p in params)
        name = func.__name__

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            for old, new in renamed.items():
                if old in kwargs:
                    if new in kwargs:
                        raise ImunoiseTypeError(
                            f"{name}() got both {new!r} and its old name {old!r}")
                    _deprecated(f"{name}({old}=...) is deprecated; use {new}=")
                    kwargs[new] = kwargs.pop(old)
            extra = args[n_positional:]
            if extra:
                if len(extra) > len(keyword_only):
                    raise ImunoiseTypeError(
                        f"{name}() takes at most {n_positional + len(keyword_only)} "
                        f"positional arguments; got {len(args)}"
                    )
                moved = keyword_only[: len(extra)]
                for option, value in zip(moved, extra, strict=True):
                    if option in kwargs:
                        raise ImunoiseTypeError(f"{name}() got multiple values for {option!r}")
                    kwargs[option] = value
                _deprecated(
                    f"passing {', '.join(moved)} to {name}() by position is deprecated; "
                    f"pass {', '.join(f'{o}=' for o in moved)} by keyword"
                )
            return func(*args[:n_positional], **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate


def _deprecated(message: str) -> None:
    # at the caller's line, past this helper and the wrapper
    _warn.warn(message, ImunoiseDeprecationWarning)
