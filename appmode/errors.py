"""The error types the command line reports as a single line on stderr: ours only (any
other exception is a bug, and shows as one)."""


class AppmodeError(Exception):
    """A user-facing error: the message says what went wrong, where, and how to fix it."""


class InvalidValue(AppmodeError, ValueError):
    """A value out of its range, or a name that is not known (a parameter, a setting, a
    drive type): a ValueError to the API, one line to the command line."""


DISTRIBUTION = "appmode-car"
"""appmode's name as pip installs it (`appmode` on PyPI is an unrelated Jupyter extension;
the import name and the command stay `appmode`: docs/development.md, "Names")."""


def install_line(extra: str) -> str:
    """How to add an extra, whether appmode came from PyPI or from a clone."""
    return f"pip install '{DISTRIBUTION}[{extra}]' (in a clone: pip install '.[{extra}]')"
