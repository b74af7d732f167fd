"""The error types the command line reports as a single line on stderr: ours only (any
other exception is a bug, and shows as one)."""


class AppmodeError(Exception):
    """A user-facing error: the message says what went wrong, where, and how to fix it."""


class InvalidValue(AppmodeError, ValueError):
    """A value out of its range, or a name that is not known (a parameter, a setting, a
    drive type): a ValueError to the API, one line to the command line."""
