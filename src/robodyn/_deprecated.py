"""Old spellings kept for one release: renamed keywords, fields and file columns.

Each use warns once per call site with a :class:`robodyn.errors.RobodynDeprecationWarning`
that names the new spelling (the vocabulary is listed in the README's conventions).
"""

from __future__ import annotations

import functools
import warnings

from .errors import RobodynDeprecationWarning


def warn_renamed(old: str, new: str, where: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` is the deprecated spelling of ``new`` in ``where``."""
    warnings.warn(f"{where}: {old!r} is deprecated, use {new!r}", RobodynDeprecationWarning,
                  stacklevel=stacklevel)


def renamed_keywords(**old_to_new: str):
    """Decorator: accept each keyword ``old`` as the deprecated spelling of ``new``.

    Passing both spellings is a ``TypeError``, as a repeated keyword is."""

    def decorate(fn):
        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{fn.__name__}() got both {old!r} (deprecated) and {new!r}")
                    warn_renamed(old, new, f"{fn.__name__}()")
                    kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        return wrapper

    return decorate


def renamed_keyword(old: str, old_value, new: str, new_value, where: str, default="local"):
    """The value of keyword ``new`` when its old spelling ``old`` was passed (``old_value``):
    warns, and raises ``TypeError`` when ``new`` was passed as well (differs from ``default``).
    For the hot entry points, where a decorator's call costs more than the check."""
    if new_value != default:
        raise TypeError(f"{where} got both {old!r} (deprecated) and {new!r}")
    warn_renamed(old, new, where, stacklevel=4)
    return old_value


def renamed_attribute(old: str, new: str) -> property:
    """A read-only property ``old`` that warns and returns attribute ``new``."""

    def get(self):
        warn_renamed(f"{type(self).__name__}.{old}", f"{type(self).__name__}.{new}", "robodyn")
        return getattr(self, new)

    return property(get, doc=f"Deprecated spelling of :attr:`{new}`.")
