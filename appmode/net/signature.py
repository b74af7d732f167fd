"""The car's host's word, signed. A key holder may run a Zenoh peer of its own with the
key, and a client that scouts may join it; so the car's host signs every reply and
sample a client acts on (Ed25519, under a key made from the room's host key: every host
of a room signs alike), each reply bound to the query it answers (whose words carry a
token of the client's), each sample to its key and the car's time of it (a replay is
older than what came). A client trusts the host id its URL gives (`id=`), else the first
it met for its key, kept in its data folder (trust on first use, as ssh's)."""

from __future__ import annotations

import base64
import hashlib
import hmac
import os
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from appmode.net.asked import json_object
from appmode.net.proof import framed
from appmode.ports.remote import HOST_ID

if TYPE_CHECKING:
    import zenoh
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey

KNOWN_FILE = "share.hosts"
"""The host ids a client met first for each key (a line each: a tag of the key, the id)."""


def _text(data: bytes) -> str:
    return base64.urlsafe_b64encode(data).decode().rstrip("=")


def _bytes(text: str) -> bytes:
    return base64.urlsafe_b64decode(text + "=" * (-len(text) % 4))


class Signer:
    """A car's host's side: it signs under the room's host key."""

    def __init__(self, host_key: str) -> None:
        from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

        seed = hmac.new(host_key.encode(), b"appmode host id", hashlib.sha256).digest()
        self._key = Ed25519PrivateKey.from_private_bytes(seed)
        self.id = _text(self._key.public_key().public_bytes_raw())

    def sign(self, *parts: str | bytes) -> str:
        """`ID SIGNATURE` of `parts`, as a reply's or sample's attachment carries it."""
        return f"{self.id} {_text(self._key.sign(framed(*parts)))}"

    def reply(self, query: zenoh.Query, key: str, payload: str) -> None:
        """Answer `query` at `key`, signed over the answer and the query's own words."""
        signed = self.sign("reply", key, payload, *_asked(query))
        query.reply(key, payload, attachment=signed)

    def put(self, publisher: Any, key: str, payload: str | bytes, stamp: bytes = b"") -> None:
        """Publish a sample of `key` (with its `stamp`, where it has one), signed."""
        signed = self.sign("sample", key, payload, stamp)
        publisher.put(payload, attachment=stamp + b" " + signed.encode() if stamp else signed)


class Trust:
    """A client's side: the car's host's id it trusts for `key` (`given`, else the one
    it met first, kept), and the ids that signed what it refused."""

    def __init__(self, key: str, given: str | None = None) -> None:
        self._tag = hashlib.sha256(b"appmode key\0" + key.encode()).hexdigest()[:16]
        self.id = given if given is not None else self._kept()
        self._public: tuple[str, Ed25519PublicKey] | None = None
        self.strangers: set[str] = set()
        """Ids that signed what this client refused (a peer that is not the car's host)."""

    def holds(self, signed: str | None, *parts: str | bytes) -> bool:
        """Whether `signed` (`ID SIGNATURE`) is the car's host's over `parts`; the first
        that holds, where no id was given or kept, makes its id the one trusted."""
        host_id, _, signature = (signed or "").partition(" ")
        if not HOST_ID.fullmatch(host_id) or not signature or len(signature) > 100:
            return False
        if self.id is not None and host_id != self.id:
            self.strangers.add(host_id)
            return False
        if not _verified(self._key(host_id), signature, framed(*parts)):
            return False
        if self.id is None:
            self.id = host_id
            self._keep(host_id)
        return True

    def replies(
        self, replies: Iterable[zenoh.Reply], attachment: str, payload: str | bytes = b""
    ) -> Iterator[zenoh.Sample]:
        """The answers the car's host signed to a query of `attachment` and `payload`,
        as they come (a forger's, and refusals it did not sign, are left)."""
        asked = (attachment.encode(), payload.encode() if isinstance(payload, str) else payload)
        for reply in replies:
            ok = reply.ok
            if ok is None:
                continue
            signed = _text_of(ok.attachment)
            answer = ok.payload.to_bytes()
            if self.holds(signed, "reply", str(ok.key_expr), answer, *asked):
                yield ok

    def answer(
        self, replies: Iterable[zenoh.Reply], attachment: str, payload: str | bytes = b""
    ) -> dict[str, Any] | None:
        """The car's host's signed answer to a query of `attachment` and `payload`, a JSON
        object; None when none came."""
        signed = self.replies(replies, attachment, payload)
        answers = (json_object(ok.payload.to_bytes()) for ok in signed)
        return next(filter(None, answers), None)

    def sample(self, sample: zenoh.Sample, stamp: bytes = b"") -> bool:
        """Whether the car's host signed `sample` (whose attachment's `stamp` is given)."""
        attachment = b"" if sample.attachment is None else sample.attachment.to_bytes()
        signed = attachment[len(stamp) + 1 :] if stamp else attachment
        text = signed.decode("ascii", "replace")
        return self.holds(text, "sample", str(sample.key_expr), sample.payload.to_bytes(), stamp)

    def refusal(self) -> str:
        """What a client that heard only others than the car's host says (or "")."""
        if not self.strangers:
            return ""
        return (
            f" (answers came from a host whose id is not the car's host's, {self.id}: a key "
            "holder's own Zenoh peer? connect= to the car's host, or check id= in the URL "
            "appmode share printed)"
        )

    def _key(self, host_id: str) -> Ed25519PublicKey:
        from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey

        if self._public is None or self._public[0] != host_id:
            self._public = (host_id, Ed25519PublicKey.from_public_bytes(_bytes(host_id)))
        return self._public[1]

    def _kept(self) -> str | None:
        try:
            lines = _known().read_text(encoding="utf-8").splitlines()
        except (OSError, UnicodeDecodeError):
            return None
        found = (line.split(" ")[1] for line in lines if line.startswith(self._tag + " "))
        return next((host_id for host_id in found if HOST_ID.fullmatch(host_id)), None)

    def _keep(self, host_id: str) -> None:
        """Keep the id met first (a client that cannot write its data folder trusts it
        for this run alone)."""
        path = _known()
        try:
            path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
            with os.fdopen(fd, "a", encoding="utf-8") as file:
                file.write(f"{self._tag} {host_id}\n")
        except OSError:
            pass


def _asked(query: zenoh.Query) -> tuple[bytes, bytes]:
    """A query's own words: its attachment and payload."""
    attachment = b"" if query.attachment is None else query.attachment.to_bytes()
    return attachment, b"" if query.payload is None else query.payload.to_bytes()


def _text_of(data: zenoh.ZBytes | None) -> str:
    return "" if data is None else data.to_bytes().decode("ascii", "replace")


def _verified(public: Ed25519PublicKey, signature: str, message: bytes) -> bool:
    from cryptography.exceptions import InvalidSignature

    try:
        public.verify(_bytes(signature), message)
    except (InvalidSignature, ValueError):
        return False
    return True


def _known() -> Path:
    from appmode.files import data_folder

    return data_folder() / KNOWN_FILE
