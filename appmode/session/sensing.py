"""The car's twist as its records show it, for the views that publish odometry (a ROS
node, a viewer): the APP port's A records read by `protocol.sensed`, with the signs of
the motion in force where they carry magnitudes and the B record's yaw where they carry
no turn."""

from __future__ import annotations

from collections.abc import Callable

from appmode.host.app.state import HostState
from appmode.protocol.sensed import Sensing, yaw_rate
from appmode.protocol.twist import Twist

Signs = Callable[[], tuple[float, float, float] | None]
YAW_HISTORY = 1.0
"""Seconds of B records before the first A record read, for its turn rate."""


def gap(state: HostState | None, signs_known: bool) -> str | None:
    """Why a session with `state` (its APP port's, if any) senses no twist; None: it
    does. `signs_known`: the port tells the signs of the motion in force."""
    if state is None:
        return "no APP port beside: no records of the car's motion"
    sensing = Sensing(state.layout)
    if sensing.gap is None and sensing.needs_signs and not signs_known:
        return (
            f"the {state.layout.profile.name} profile's A record carries magnitudes, which "
            "only the control port's frames sign: drive its control port (--uart2)"
        )
    return sensing.gap


def twists(state: HostState, signs: Signs, after: float) -> list[tuple[float, Twist]]:
    """The twist each A record of `state` since `after` shows, in time order."""
    sensing = Sensing(state.layout)
    fresh = [(at, event) for at, event in state.velocities.points if at > after]
    if not fresh:
        return []
    in_force = signs() if sensing.needs_signs else None
    yaws: list[tuple[float, float]] = []
    if sensing.turn_from_yaw:
        index = sensing.yaw
        assert index is not None
        start = fresh[0][0] - YAW_HISTORY
        yaws = [(at, event.values[index]) for at, event in state.attitudes.points if at >= start]
    found = []
    for at, event in fresh:
        rate = yaw_rate(yaws, at) if sensing.turn_from_yaw else None
        twist = sensing.twist(event.values, in_force, rate)
        if twist is not None:
            found.append((at, twist))
    return found
