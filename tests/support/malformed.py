"""A key holder's malformed queries to a shared car, as no appmode client sends them:
`python -m tests.support.malformed ENDPOINT KEY NAME` sends a `get appmode/**` with a
write's payload, a write and a lease with attachments that are not UTF-8, and a lease
of JSON that does not parse, and prints each one's answers (`ok:KEY` or `error`) as a
line."""

from __future__ import annotations

import sys

from appmode.net.config import close_session, open_session
from appmode.net.names import Keys


def main(endpoint: str, key: str, name: str) -> None:
    session = open_session("client", key, connect=(endpoint,))
    keys = Keys(name)
    asked = [
        ("wildcard", "appmode/**", b"A", b"someone-1-abc"),
        ("write", keys.write("app"), b"A", b"\xff\xfe-1-abc"),
        ("lease", keys.lease, b"{}", b"\xff\xfe-1-abc"),
        ("json", keys.lease, b"{not json", b"someone-1-abc"),
    ]
    try:
        for what, key_expr, payload, attachment in asked:
            replies = list(session.get(key_expr, payload=payload, attachment=attachment))
            said = [f"ok:{r.ok.key_expr}" if r.ok is not None else "error" for r in replies]
            print(what, " ".join(said) or "none", flush=True)
    finally:
        close_session(session)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3])
