"""The shipped profiles' module (`appmode/protocol/profiles/__init__.py`), made from the
TOML files beside it: each file's text, and its TOML as read, so that appmode reads
neither a file nor tomllib to know them. After editing a shipped profile's file:

    python -m tests.support.shipped_profiles

(tests/protocol/test_profile_file.py fails while the module and the files differ)."""

from __future__ import annotations

import pprint
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10
    import tomli as tomllib

from appmode.protocol.profile_file import SHIPPED

FOLDER = Path(__file__).resolve().parents[2] / "appmode" / "protocol" / "profiles"
MODULE = FOLDER / "__init__.py"
HEAD = '''"""The profiles appmode ships, as data: each file's text (`TEXTS`, what `profile show
--toml` prints) and its TOML as read (`DATA`). Made from the files beside it by
`python -m tests.support.shipped_profiles`: edit those, then run it."""
# ruff: noqa: E501

'''


def render() -> str:
    """The module's text, from the files as they are now."""
    texts = {name: (FOLDER / f"{name}.toml").read_text(encoding="utf-8") for name in SHIPPED}
    data = {name: tomllib.loads(text) for name, text in texts.items()}
    shown = {
        name: pprint.pformat(value, width=160, sort_dicts=False)
        for name, value in (("texts", texts), ("data", data))
    }
    return (
        HEAD
        + f"TEXTS: dict[str, str] = {shown['texts']}\n\n"
        + f"DATA: dict[str, dict[str, object]] = {shown['data']}\n"
    )


if __name__ == "__main__":
    MODULE.write_text(render(), encoding="utf-8")
    sys.exit(0)
