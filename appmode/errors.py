"""The one error type the command line reports as a single line on stderr."""


class AppmodeError(Exception):
    """A user-facing error: the message says what went wrong, where, and how to fix it."""
