"""The car's parameters as the node's ROS 2 parameters (rcl_interfaces' services, as
rclcpp's ParameterService answers them): listed, read, typed and described from the
session's table, and set through the session's own verified set — one at a time, in the
order asked, each answered once the value read back shows it (or the board kept
another). Nothing here is saved: `save` (std_srvs/Trigger) sends the board's save."""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from appmode.errors import AppmodeError
from appmode.protocol import param_values
from appmode.protocol.profile_file import ParamSpec

if TYPE_CHECKING:
    from appmode.session.base import BaseSession

NOT_SET, INTEGER, DOUBLE = 0, 2, 3
"""rcl_interfaces/msg/ParameterType's values used here."""
TYPE_NAMES = {0: "not set", 1: "bool", 2: "integer", 3: "double", 4: "string"}
SETS = 32
"""Set requests waiting at most; one more is answered at once as refused."""
Reply = Callable[[Any], None]
SERVICES = {
    "~/describe_parameters": "rcl_interfaces/srv/DescribeParameters",
    "~/get_parameter_types": "rcl_interfaces/srv/GetParameterTypes",
    "~/get_parameters": "rcl_interfaces/srv/GetParameters",
    "~/list_parameters": "rcl_interfaces/srv/ListParameters",
    "~/set_parameters": "rcl_interfaces/srv/SetParameters",
    "~/set_parameters_atomically": "rcl_interfaces/srv/SetParametersAtomically",
    "~/save": "std_srvs/srv/Trigger",
}
"""The node's services (as rclcpp's ParameterService names them, and `save`)."""


@dataclass
class Setting:
    """A set request under way: its parameters, the results so far, where to answer."""

    wanted: list[tuple[str, Any]]
    reply: Reply
    atomic: bool
    results: list[tuple[bool, str]] = field(default_factory=list)
    asked: str | None = None
    """The parameter whose set the session runs now (None: none started yet)."""
    errors: list[str] = field(default_factory=list)


class Parameters:
    """The parameter services' answers for `session`, made with `types` (the distro's
    rcl_interfaces messages); taken on the node's loop, never on Zenoh's threads."""

    def __init__(
        self, session: BaseSession, types: Any, node: str, on_event: Reply | None = None
    ) -> None:
        self.session = session
        self.types = types
        self.node = node
        """The node's full name (`/appmode`), as its parameter events name it."""
        self.on_event = on_event
        """Takes each rcl_interfaces/ParameterEvent (a value set, read back)."""
        self._sets: deque[Setting] = deque()

    def answer(self, ros_type: str, request: Any, reply: Reply) -> None:
        """Answer `request` of the service type `ros_type` (a set: once it is done)."""
        reads = {
            "rcl_interfaces/srv/ListParameters": self.list,
            "rcl_interfaces/srv/GetParameters": self.get,
            "rcl_interfaces/srv/GetParameterTypes": self.types_of,
            "rcl_interfaces/srv/DescribeParameters": self.describe,
            "std_srvs/srv/Trigger": self.save,
        }
        if ros_type in reads:
            reply(reads[ros_type](request))
        else:
            self.set(request, reply, atomic=ros_type.endswith("Atomically"))

    def save(self, request: Any) -> Any:
        """The session's `save`: success when it was sent, its line as the message (the
        board confirms no save)."""
        failures = self.session.failures
        self.session.run("save")
        said = self.session.messages[-1] if self.session.messages else ""
        return self.types["std_srvs/srv/Trigger_Response"](
            success=self.session.failures == failures, message=said
        )

    # ------------------------------------------------------------ what is read

    def _specs(self) -> dict[str, ParamSpec]:
        return {spec.name: spec for spec in self.session.parameter_specs()}

    def _make(self, kind: str, **fields: Any) -> Any:
        return self.types[f"rcl_interfaces/{kind}"](**fields)

    def _value(self, spec: ParamSpec | None, value: int | float | None) -> Any:
        kind = NOT_SET if spec is None or value is None else _type(spec)
        return self._make(
            "msg/ParameterValue",
            type=kind,
            bool_value=False,
            integer_value=int(value) if kind == INTEGER and value is not None else 0,
            double_value=float(value) if kind == DOUBLE and value is not None else 0.0,
            string_value="",
            byte_array_value=_empty("uint8"),
            bool_array_value=_empty("bool"),
            integer_array_value=_empty("int64"),
            double_array_value=_empty("float64"),
            string_array_value=[],
        )

    def list(self, request: Any) -> Any:
        """Names under the prefixes asked (all without any); the car's have no dots."""
        prefixes = list(request.prefixes)
        names = [
            name
            for name in self._specs()
            if not prefixes or any(name == p or name.startswith(f"{p}.") for p in prefixes)
        ]
        result = self._make("msg/ListParametersResult", names=names, prefixes=[])
        return self._make("srv/ListParameters_Response", result=result)

    def get(self, request: Any) -> Any:
        """Each value as last read (not set: unknown, or not read yet)."""
        specs, values = self._specs(), self.session.parameters()
        found = [self._value(specs.get(n), values.get(n)) for n in request.names]
        return self._make("srv/GetParameters_Response", values=found)

    def types_of(self, request: Any) -> Any:
        specs = self._specs()
        kinds = [_type(specs[n]) if n in specs else NOT_SET for n in request.names]
        return self._make("srv/GetParameterTypes_Response", types=_array(kinds))

    def describe(self, request: Any) -> Any:
        """Each parameter's type, label and range in the user's units (its step: one
        of the frame's integers)."""
        specs = self._specs()
        return self._make(
            "srv/DescribeParameters_Response",
            descriptors=[self._descriptor(n, specs.get(n)) for n in request.names],
        )

    def _descriptor(self, name: str, spec: ParamSpec | None) -> Any:
        floats: list[Any] = []
        integers: list[Any] = []
        if spec is not None and _type(spec) == DOUBLE:
            low, high = (param_values.user_number(spec, v) for v in (spec.minimum, spec.maximum))
            step = param_values.user_number(spec, 1)
            floats.append(
                self._make("msg/FloatingPointRange", from_value=low, to_value=high, step=step)
            )
        elif spec is not None:
            integers.append(
                self._make(
                    "msg/IntegerRange", from_value=spec.minimum, to_value=spec.maximum, step=1
                )
            )
        return self._make(
            "msg/ParameterDescriptor",
            name=name,
            type=NOT_SET if spec is None else _type(spec),
            description="" if spec is None else spec.label,
            additional_constraints=(
                ""
                if spec is None
                else "set on the board, verified by reading it back; the "
                "node's save service (std_srvs/Trigger) writes it to flash"
            ),
            read_only=False,
            dynamic_typing=False,
            floating_point_range=floats,
            integer_range=integers,
        )

    # ------------------------------------------------------------ sets

    def set(self, request: Any, reply: Reply, atomic: bool) -> None:
        """Start (or queue) a set of `request.parameters`; `reply` gets the response."""
        wanted = [(p.name, p.value) for p in request.parameters]
        setting = Setting(wanted, reply, atomic)
        if len(self._sets) >= SETS:
            self._answer(setting, "refused: too many sets wait (the board takes one at a time)")
            return
        if atomic and len(wanted) > 1:
            why = (
                "the board takes one parameter at a time: set them with set_parameters "
                "(ros2 param set), each verified"
            )
            self._answer(setting, why)
            return
        self._sets.append(setting)

    def said(self, text: str) -> None:
        """A line the session said: an error while a set runs is why it failed."""
        if self._sets and self._sets[0].asked is not None and text.startswith("error:"):
            self._sets[0].errors.append(text.removeprefix("error: "))

    def serve(self) -> None:
        """Go on with the sets, one parameter at a time (at each turn of the loop)."""
        while self._sets and not self.session.busy:
            setting = self._sets[0]
            if setting.asked is not None:
                setting.results.append(self._outcome(setting))
                if setting.results[-1][0]:
                    self._changed(setting.asked)
                setting.asked = None
            if len(setting.results) == len(setting.wanted):
                self._sets.popleft()
                self._reply(setting)
                continue
            name, value = setting.wanted[len(setting.results)]
            self._start(setting, name, value)

    def _start(self, setting: Setting, name: str, value: Any) -> None:
        spec = self._specs().get(name)
        why = _refusal(spec, name, value, list(self._specs()))
        if why is None and spec is not None:
            setting.errors.clear()
            try:
                self.session.set_parameter(name, _text(value))
            except AppmodeError as exc:
                why = str(exc)
            else:
                setting.asked = name
                return
        setting.results.append((False, why or "refused"))

    def _outcome(self, setting: Setting) -> tuple[bool, str]:
        """The set just done: successful when the value read back is the one asked."""
        name = setting.asked or ""
        index = len(setting.results)
        value = setting.wanted[index][1]
        spec = self._specs()[name]
        wanted = param_values.user_number(spec, param_values.from_user(spec, _text(value)))
        now = self.session.parameters().get(name)
        if now == wanted:
            return True, ""
        why = "; ".join(setting.errors) or f"the board reads back {name} = {now}"
        return False, f"not set: {why}"

    def _changed(self, name: str) -> None:
        """Say on /parameter_events that `name` changed, as rclcpp's nodes do."""
        if self.on_event is None:
            return
        value = self._value(self._specs().get(name), self.session.parameters().get(name))
        now = time.time_ns()
        stamp = self.types["builtin_interfaces/msg/Time"](sec=now // 10**9, nanosec=now % 10**9)
        event = self._make(
            "msg/ParameterEvent",
            stamp=stamp,
            node=self.node,
            new_parameters=[],
            changed_parameters=[self._make("msg/Parameter", name=name, value=value)],
            deleted_parameters=[],
        )
        self.on_event(event)

    def _answer(self, setting: Setting, why: str) -> None:
        setting.results = [(False, why)] * max(1, len(setting.wanted))
        self._reply(setting)

    def _reply(self, setting: Setting) -> None:
        results = [
            self._make("msg/SetParametersResult", successful=ok, reason=why)
            for ok, why in setting.results
        ]
        if setting.atomic:
            response = self._make("srv/SetParametersAtomically_Response", result=results[0])
        else:
            response = self._make("srv/SetParameters_Response", results=results)
        setting.reply(response)


def _type(spec: ParamSpec) -> int:
    return INTEGER if spec.scale == 1 else DOUBLE


def _text(value: Any) -> str:
    """A ParameterValue as the user's text (an integer, or a double's shortest form)."""
    return str(value.integer_value) if value.type == INTEGER else repr(value.double_value)


def _refusal(spec: ParamSpec | None, name: str, value: Any, names: list[str]) -> str | None:
    """Why a set of `value` is refused before it reaches the board, or None."""
    if spec is None:
        return f"no parameter {name!r}: the car's are {', '.join(names) or 'none here'}"
    if value.type == NOT_SET:
        return f"{name} cannot be undeclared: it is the car's"
    if value.type not in (INTEGER, DOUBLE) or (value.type == DOUBLE and _type(spec) == INTEGER):
        given = TYPE_NAMES.get(value.type, str(value.type))
        return f"{name} is {TYPE_NAMES[_type(spec)]}, not {given}"
    return None


def _empty(kind: str) -> Any:
    return np.zeros(0, dtype=kind)


def _array(values: list[int]) -> Any:
    return np.array(values, dtype="uint8")
