"""What a host tells besides the protocol's events, on either port."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class LinkStatus:
    """The link went down (`up` False) or came back."""

    up: bool
    text: str


@dataclass(frozen=True, slots=True)
class BoardWarning:
    """The board does not do what it was told: the car still moves after a stop."""

    text: str


@dataclass(frozen=True, slots=True)
class FarStop:
    """The far end (a shared car's host) stopped the car (`stopped`), or could not."""

    text: str
    stopped: bool = True
