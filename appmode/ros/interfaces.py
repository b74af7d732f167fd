"""The ROS 2 services the node serves, with no I/O: each request's and response's
definition (rcl_interfaces' parameter services, std_srvs' Trigger), registered in the
distro's type store for CDR, and each service's RIHS01 type hash (REP-2016).

A service's type description is a message of three fields, `request_message`,
`response_message` and `event_message`, the event being `info`
(service_msgs/ServiceEventInfo) with at most one request and one response; its
`client_gid` is `uint8[16]` as the IDL writes it (the .msg file's `char` is an alias).
rosbags hashes such a description when it is registered as a message: with these, it
gives rmw_zenoh's documented example_interfaces/srv/AddTwoInts
`RIHS01_e118de6b…` (tests/ros/test_vectors.py)."""

from __future__ import annotations

from functools import cache
from typing import Any

from rosbags.typesys import get_types_from_msg
from rosbags.typesys.store import Typestore

SERVICES = {
    "rcl_interfaces/srv/ListParameters": (
        "string[] prefixes\nuint64 depth",
        "rcl_interfaces/ListParametersResult result",
    ),
    "rcl_interfaces/srv/GetParameters": (
        "string[] names",
        "rcl_interfaces/ParameterValue[] values",
    ),
    "rcl_interfaces/srv/GetParameterTypes": ("string[] names", "uint8[] types"),
    "rcl_interfaces/srv/DescribeParameters": (
        "string[] names",
        "rcl_interfaces/ParameterDescriptor[] descriptors",
    ),
    "rcl_interfaces/srv/SetParameters": (
        "rcl_interfaces/Parameter[] parameters",
        "rcl_interfaces/SetParametersResult[] results",
    ),
    "rcl_interfaces/srv/SetParametersAtomically": (
        "rcl_interfaces/Parameter[] parameters",
        "rcl_interfaces/SetParametersResult result",
    ),
    "std_srvs/srv/Trigger": ("", "bool success\nstring message"),
}
"""Each service type the node serves: its request's and its response's fields."""
EVENT_INFO = (
    "uint8 event_type\nbuiltin_interfaces/Time stamp\nuint8[16] client_gid\nint64 sequence_number"
)
"""service_msgs/msg/ServiceEventInfo as its IDL has it."""
INFO = "service_msgs/msg/ServiceEventInfo"
Fields = dict[str, Any]


def _message(text: str) -> Any:
    """The rosbags definition of the message whose fields are `text`."""
    ((_, definition),) = get_types_from_msg(text, "appmode/msg/Defined").items()
    return _renamed(definition)


def _renamed(value: Any) -> Any:
    """A definition with its references to `pkg/srv/msg/X` (rosbags' form for a name
    under srv/) written `pkg/srv/X`, as ROS names them."""
    if isinstance(value, str):
        return value.replace("/srv/msg/", "/srv/")
    if isinstance(value, tuple | list):
        return type(value)(_renamed(item) for item in value)
    return value


def definitions(service: str) -> Fields:
    """A service's request and response, as rosbags defines messages."""
    request, response = SERVICES[service]
    return {
        f"{service}_Request": _message(request),
        f"{service}_Response": _message(response),
    }


def register(store: Any) -> None:
    """Put every service's request and response in `store`, for CDR."""
    for service in SERVICES:
        store.register(definitions(service))


@cache
def service_hash(service: str, base: Any) -> str:
    """The RIHS01 hash of `service`, its message types taken from the store `base`."""
    hashing = Typestore()
    hashing.register({name: kind for name, kind in base.fielddefs.items() if name != INFO})
    hashing.register({INFO: _message(EVENT_INFO)})
    hashing.register(definitions(service))
    event = f"service_msgs/ServiceEventInfo info\n{service}_Request[<=1] request\n"
    event += f"{service}_Response[<=1] response"
    whole = f"{service}_Request request_message\n{service}_Response response_message\n"
    whole += f"{service}_Event event_message"
    hashing.register({f"{service}_Event": _message(event)})
    hashing.register({service: _message(whole)})
    return str(hashing.hash_rihs01(service))
