"""Helpers that keep the public API stable while it is tidied: options that used to
be positional or had another name keep working for one release, with a
``DeprecationWarning`` that says what to write instead."""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


def positional_options(positional: int, *names: str) -> Callable[[F], F]:
    """Accept the keyword-only ``names`` positionally after the first
    ``positional`` arguments, as the function did before, with a warning."""

    def wrap(func: F) -> F:
        @functools.wraps(func)
        def inner(*args, **kwargs):
            extra = args[positional:]
            if extra:
                if len(extra) > len(names):
                    raise TypeError(
                        f"{func.__name__}() takes {positional} positional arguments; "
                        f"got {len(args)}"
                    )
                moved = dict(zip(names, extra, strict=False))
                clash = set(moved) & set(kwargs)
                if clash:
                    raise TypeError(f"{func.__name__}() got multiple values for {sorted(clash)}")
                warnings.warn(
                    f"passing {', '.join(moved)} to {func.__name__}() by position is "
                    f"deprecated; write {', '.join(f'{k}=...' for k in moved)}",
                    DeprecationWarning, stacklevel=2,
                )
                kwargs.update(moved)
            return func(*args[:positional], **kwargs)

        return inner  # type: ignore[return-value]

    return wrap


def renamed_keyword(old: str, new: str) -> Callable[[F], F]:
    """Accept keyword ``old`` as ``new`` for one release, with a warning."""

    def wrap(func: F) -> F:
        @functools.wraps(func)
        def inner(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise TypeError(f"{func.__name__}() got both {old!r} and {new!r}")
                warnings.warn(
                    f"{func.__name__}({old}=...) is deprecated; write {new}=...",
                    DeprecationWarning, stacklevel=2,
                )
                kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        return inner  # type: ignore[return-value]

    return wrap
