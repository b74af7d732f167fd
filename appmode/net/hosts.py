"""One name, one car: each host that shares a car holds a liveliness token of its own
for the car's name (`names.Keys.host`), and a share that finds another host's token on
its key does not serve (a cloned configuration, two Pis with one `--name`: one driver
would drive both)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from appmode.errors import AppmodeError
from appmode.net.names import Keys

if TYPE_CHECKING:
    import zenoh

HOSTS_WAIT = 1.0
"""Seconds a share asks for other hosts of its car's name before it serves it."""


def claim(session: zenoh.Session, keys: Keys) -> Any:
    """This host's token for the car (undeclare it to let go); AppmodeError when another
    host shares a car of this name on this key."""
    zid = str(session.zid())
    token: Any = session.liveliness().declare_token(keys.host(zid))
    replies = session.liveliness().get(keys.host("*"), timeout=HOSTS_WAIT)
    others = {str(r.ok.key_expr).rsplit("/", 1)[1] for r in replies if r.ok is not None}
    if others - {zid}:
        token.undeclare()
        raise AppmodeError(
            f"a car named {keys.name} is shared already on this key (by another host): one "
            "name, one car: give this one another --name"
        )
    return token
