"""Error and warning classes of robodyn (see the error catalogue in the README)."""


class ModelError(ValueError):
    """A robot description is invalid; the message names the file, element and line."""


class RobodynWarning(UserWarning):
    """Something in an input was ignored or changed; the message says what."""


class RobodynDeprecationWarning(FutureWarning):
    """An old spelling (a keyword, a field, a file column) was used; the message gives the
    new one. The old spellings keep working for one release. A ``FutureWarning``, so that
    users of scripts and of the command line see it."""
