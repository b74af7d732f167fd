"""Who may say what on a shared car's keys, as Zenoh's own access control enforces it
at every car's host and router (the network guide's trust model). A key holder (user
`appmode`, the key its password) asks, watches, beats and holds a driver's token; only
a car's host (user `appmode-host`, the room's host key its password) publishes what a
car says, answers for it and holds its tokens. A host applies the rules to what comes
in on the links key holders opened, so nothing a key holder sends as a car goes on."""

from __future__ import annotations

from typing import Any

from appmode.net.names import USER, Keys

_CAR = Keys("*")
RULES: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "a car's words": (
        ("put", "delete"),
        (_CAR.events, _CAR.records, _CAR.info, _CAR.bytes("*")),
    ),
    "a car's tokens": (("liveliness_token",), (_CAR.presence, _CAR.host("*"))),
    "answers": (("declare_queryable", "reply"), ("**",)),
}
"""What a key holder may not send (its messages, on these key expressions): one table."""


def access_control() -> dict[str, Any]:
    """Zenoh's `access_control` configuration of a car's host or router."""
    rules = [
        {
            "id": name,
            "permission": "deny",
            "flows": ["ingress"],
            "messages": list(messages),
            "key_exprs": list(keys),
        }
        for name, (messages, keys) in RULES.items()
    ]
    return {
        "enabled": True,
        "default_permission": "allow",
        "rules": rules,
        "subjects": [{"id": "key holders", "usernames": [USER]}],
        "policies": [{"rules": list(RULES), "subjects": ["key holders"]}],
    }
