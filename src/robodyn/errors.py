"""Error and warning classes of robodyn (see the error catalogue in the README)."""


class ModelError(ValueError):
    """A robot description is invalid; the message names the file, element and line."""


class RobodynWarning(UserWarning):
    """Something in an input was ignored or changed; the message says what."""
