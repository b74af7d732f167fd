"""What a profile's records hold, for a host that names them: the A record's four fields
(the sheet's signed velocity, the reference firmware's |0.7·x|, |0.7·y| and battery, the
balance car's encoders and angle), the B record's fields and the C record's parameters.
The grammar is the same for the whole family; a host that shows or checks the fields
picks a layout (`--profile`); every layout comes from a profile's file."""

from __future__ import annotations

from appmode.protocol import profile_file
from appmode.protocol.app_decoders import BoardDecoder
from appmode.protocol.profile_file import Field, ParamSpec, ProfileFile
from appmode.protocol.slotted import Frozen

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short


class Layout(Frozen):
    """One reading of `{A<f0>:<f1>:<f2>:<f3>}$`, `{B…}$` and `{C…}$`: a profile file's."""

    _fields = ("name", "profile")
    _shown = ("name", "a_fields", "b_fields", "params", "replies")  # hashable: not the file's
    __slots__ = (
        *_fields,
        "a_fields",
        "b_fields",
        "params",
        "replies",
        "fields",
        "labels",
        "motion",
        "scale",
        "signed",
        "battery",
        "b_names",
        "param_names",
        "extra_a",
        "speed_index",
        "sheet_b",
    )
    name: str
    profile: ProfileFile
    a_fields: tuple[Field, ...]
    """The A record's four fields."""
    b_fields: tuple[Field, ...]
    """The B record's fields."""
    params: tuple[ParamSpec, ...]
    """The C record's fields: the parameters, with their ranges and scales."""
    replies: tuple[bytes, ...]
    """What the board sends besides records (`##$`)."""
    fields: tuple[str, str, str, str]
    """The A fields' names (JSON keys), in order."""
    labels: tuple[str, str, str, str]
    """The A fields' names for people."""
    motion: tuple[int, ...]
    """The A fields that grow with the car's speed."""
    scale: float
    """field = scale × velocity for the motion fields (they share one scale)."""
    signed: bool
    """Whether the motion fields carry a sign (else they are magnitudes)."""
    battery: int | None
    """The A field holding the battery percentage, if any."""
    b_names: tuple[str, ...]
    param_names: tuple[str, ...]
    extra_a: tuple[int, ...]
    """The A fields shown besides the motion and the battery: those with a unit (the
    balance car's angle; not the sheet's `extra`)."""
    speed_index: int | None
    """The parameter the speed keys change (max_speed), or None: the profile has none."""
    sheet_b: bool
    """Its B record is the sheet's: pitch, roll, yaw, battery (an `Attitude`)."""

    def __init__(self, name: str, profile: ProfileFile) -> None:
        a = profile.a
        motion = tuple(i for i, field in enumerate(a) if field.motion)
        first = a[motion[0]] if motion else a[0]
        battery = next((i for i, field in enumerate(a) if field.battery), None)
        b_names = tuple(field.name for field in profile.b)
        param_names = tuple(param.name for param in profile.params)
        speed = profile.speed_param
        self._fill(name, profile)
        derived = {
            "a_fields": a,
            "b_fields": profile.b,
            "params": profile.params,
            "replies": tuple(reply.encode() for reply in profile.replies),
            "fields": tuple(field.name for field in a),
            "labels": tuple(field.label for field in a),
            "motion": motion,
            "scale": first.scale,
            "signed": first.signed,
            "battery": battery,
            "b_names": b_names,
            "param_names": param_names,
            "extra_a": tuple(
                i for i, field in enumerate(a) if field.unit and i not in motion and i != battery
            ),
            "speed_index": None if speed is None else param_names.index(speed),
            "sheet_b": b_names == tuple(f.name for f in profile_file.shipped("sheet").b),
        }
        for key, value in derived.items():
            object.__setattr__(self, key, value)

    def speed(self, values: tuple[int, ...]) -> float:
        """The largest speed the motion fields show, in the board's velocity unit."""
        return max(abs(values[i]) for i in self.motion) / self.scale

    def board_decoder(self) -> BoardDecoder:
        """A decoder of the board's records with this layout's field counts."""
        return BoardDecoder(len(self.b_fields), len(self.params))


VELOCITY = Layout("velocity", profile_file.shipped("sheet"))
if TYPE_CHECKING:
    SCALED: Layout
    A_LAYOUTS: dict[str, Layout]


def __getattr__(name: str) -> object:
    """SCALED (the reference firmware's layout) and A_LAYOUTS (every shipped one), made
    when first asked for: `appmode decode` reads the sheet's alone (start-up)."""
    if name == "SCALED":
        value: object = Layout("scaled", profile_file.shipped("minibalance"))
    elif name == "A_LAYOUTS":
        scaled = __getattr__("SCALED")
        assert isinstance(scaled, Layout)
        value = {layout.name: layout for layout in (VELOCITY, scaled)}
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value
