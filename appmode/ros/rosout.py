"""What the node says, as rcl carries it on /rosout: the topic's QoS and a line's level."""

from __future__ import annotations

from appmode.ros.graph import Durability, Qos

QOS = Qos(depth=1000, durability=Durability.TRANSIENT_LOCAL, lifespan=(10, 0))
"""/rosout's QoS, as rcl's (rcl_qos_profile_rosout_default)."""
LEVELS = {"error:": 40, "WARNING": 30}
"""rcl_interfaces/Log's ERROR and WARN, for the lines that start so."""
INFO = 20


def level(text: str) -> int:
    """The level of a line of the node's or its session's: ERROR, WARN, else INFO."""
    return next((n for start, n in LEVELS.items() if text.startswith(start)), INFO)
