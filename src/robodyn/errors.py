"""Error and warning classes of robodyn (see the error catalogue in the README)."""


class ModelError(ValueError):
    """A robot description is invalid; the message names the file, element and line."""


class RobodynWarning(UserWarning):
    """Something in an input was ignored or changed; the message says what."""


class RobodynDeprecationWarning(FutureWarning):
    """An old spelling (a keyword, a field, a file column) was used; the message gives the
    new one. The old spellings keep working for one release. A ``FutureWarning``, so that
    users of scripts and of the command line see it."""


def user_stacklevel() -> int:
    """The ``stacklevel`` for ``warnings.warn`` (called in the function that calls this) that
    points at the first caller outside the robodyn package: the user's line, however many of
    robodyn's functions lie between."""
    import os
    import sys

    package = os.path.dirname(os.path.abspath(__file__)) + os.sep
    level, frame = 1, sys._getframe(1)
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    return level
