"""What the four fields of an A record mean (§3.1, §13): the sheet's signed velocity, or
the reference firmware's |0.7·x|, |0.7·y| and battery. The grammar is the same; a host
that shows or checks the fields picks a layout (`--profile`); both come from the
profiles' files."""

from __future__ import annotations

from appmode.protocol import profile_file
from appmode.protocol.slotted import Frozen


class ALayout(Frozen):
    """One reading of `{A<f0>:<f1>:<f2>:<f3>}$`."""

    __slots__ = _fields = _shown = (
        "name",
        "fields",
        "motion",
        "scale",
        "signed",
        "labels",
        "battery",
    )
    name: str
    fields: tuple[str, str, str, str]
    """The fields' names (JSON keys), in order."""
    motion: tuple[int, ...]
    """The fields that grow with the car's speed."""
    scale: float
    """field = scale × velocity for the motion fields."""
    signed: bool
    """Whether the motion fields carry a sign (else they are magnitudes)."""
    labels: tuple[str, str, str, str]
    """The fields' names for people."""
    battery: int | None
    """The field holding the battery percentage, if any."""

    def __init__(
        self,
        name: str,
        fields: tuple[str, str, str, str],
        motion: tuple[int, ...],
        scale: float,
        signed: bool,
        labels: tuple[str, str, str, str],
        battery: int | None = None,
    ) -> None:
        self._fill(name, fields, motion, scale, signed, labels, battery)

    def speed(self, values: tuple[int, ...]) -> float:
        """The largest speed the motion fields show, in the board's velocity unit."""
        return max(abs(values[i]) for i in self.motion) / self.scale


def from_profile(name: str, profile: profile_file.ProfileFile) -> ALayout:
    """The A record's layout a profile file declares (its motion fields share one scale
    and signedness)."""
    fields = profile.a
    motion = tuple(i for i, field in enumerate(fields) if field.motion)
    first = fields[motion[0]] if motion else fields[0]
    battery = next((i for i, field in enumerate(fields) if field.battery), None)
    return ALayout(
        name,
        tuple(field.name for field in fields),  # type: ignore[arg-type]  # four: checked
        motion,
        first.scale,
        first.signed,
        tuple(field.label for field in fields),  # type: ignore[arg-type]
        battery,
    )


VELOCITY = from_profile("velocity", profile_file.load("sheet"))
SCALED = from_profile("scaled", profile_file.load("minibalance"))
A_LAYOUTS: dict[str, ALayout] = {layout.name: layout for layout in (VELOCITY, SCALED)}
