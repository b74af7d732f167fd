"""`appmode ros`: the car as a ROS 2 node on rmw_zenoh's wire, with no ROS installed
here — `cmd_vel` drives it (the same stop authority as every session), `odom`, `tf`,
`battery_state`, `imu` and `~/raw` come from its records."""

from __future__ import annotations

import argparse
import os
import sys
from contextlib import ExitStack

from appmode.cli.commands import COMMANDS
from appmode.cli.live_view import LiveViews, add_foxglove
from appmode.cli.options import (
    HOLDS,
    Subparsers,
    add_car,
    add_chassis,
    add_profile,
    add_uart2,
    board_choice,
    endpoint,
)
from appmode.errors import AppmodeError, install_line

ROUTER = "tcp/localhost:7447"
"""Where rmw_zenoh's sessions find their router (docs/design.md: the default config)."""
LISTEN = "tcp/localhost:0"
"""Where the node's session takes peers: this machine only, as rmw_zenoh's does."""


def register(sub: Subparsers) -> argparse.ArgumentParser:
    ros = sub.add_parser(
        "ros",
        help=COMMANDS["ros"],
        description="Run the car at URL as a ROS 2 node on rmw_zenoh (ROS_DOMAIN_ID, the "
        "router on tcp/localhost:7447, CDR, rmw_zenoh's liveliness tokens), with no ROS "
        "installed here: ROS 2 machines with RMW_IMPLEMENTATION=rmw_zenoh_cpp see the "
        "node, its topics and their types. cmd_vel (geometry_msgs/Twist) drives the car, "
        "over the control port as velocity frames (URL2, --uart2, or a sim:// board), on "
        "the APP port as the nearest of its eight directions at the speed asked; with no "
        "cmd_vel for --cmd-vel-timeout seconds the car stops. odom, tf (odom → "
        "base_link), battery_state, imu and ~/raw come from its records; the car's parameters "
        "are the node's (ros2 param; a set is verified by reading it back, ~/save writes "
        "them to flash); its lines go to /rosout. Ctrl-C or "
        "SIGTERM stops the car and withdraws the node. Needs the ros extra.",
    )
    add_car(ros)
    add_uart2(ros, "drive over the URL's own control port (a sim:// board's, a zenoh:// car's)")
    add_chassis(ros, "drive a WHEELTEC car as its vendor's driver does, over its chassis port")
    ros.add_argument(
        "--connect",
        action="append",
        type=endpoint,
        metavar="ENDPOINT",
        help=f"the Zenoh router (default {ROUTER}, as rmw_zenoh; may be given more than once)",
    )
    ros.add_argument(
        "--router",
        action="store_true",
        help="run the router in this process, listening where --connect says: for a "
        "machine that runs no `ros2 run rmw_zenoh_cpp rmw_zenohd`",
    )
    ros.add_argument(
        "--domain",
        type=_domain,
        default=None,
        metavar="N",
        help="the ROS domain (default: ROS_DOMAIN_ID, else 0)",
    )
    ros.add_argument("--namespace", default="/", metavar="NS", help="the node's namespace")
    ros.add_argument("--node", default="appmode", metavar="NAME", help="the node's name")
    ros.add_argument(
        "--distro",
        choices=("jazzy", "humble"),
        default="jazzy",
        help="the ROS the graph runs: jazzy and later write RIHS01 type hashes, humble's "
        "rmw_zenoh none (default jazzy)",
    )
    ros.add_argument(
        "--stamped",
        action="store_true",
        help="cmd_vel is geometry_msgs/TwistStamped (as Jazzy's Nav2 sends it)",
    )
    ros.add_argument(
        "--topics",
        choices=("appmode", "wheeltec"),
        default="appmode",
        help="the topics and frames published: appmode's (odom, /tf, imu, battery_state in "
        "base_link) or WHEELTEC's driver's (odom in odom_combined → base_footprint, "
        "imu/data_raw in gyro_link, PowerVoltage in volts, no TF), for its launch files",
    )
    _add_frames(ros)
    ros.add_argument(
        "--cmd-vel-timeout",
        type=float,
        default=0.5,
        metavar="SECONDS",
        help="stop the car after this long without a cmd_vel (default 0.5)",
    )
    add_profile(ros, f"the car's profile, {HOLDS}", default=None)
    add_foxglove(ros, "the car", drives=True)
    return ros


def _domain(text: str) -> int:
    if not text.isdigit() or not 0 <= int(text) <= 232:
        raise argparse.ArgumentTypeError(f"{text!r} is not a ROS domain: 0 to 232")
    return int(text)


def run(args: argparse.Namespace) -> int:
    from appmode.net.config import zenoh_module
    from appmode.ros.graph import BadName, namespace, node_name

    zenoh_module()
    _ros_module()
    if not 0.05 <= args.cmd_vel_timeout <= 10:
        raise AppmodeError("--cmd-vel-timeout: between 0.05 and 10 seconds")
    try:
        names = (namespace(args.namespace), node_name(args.node))
    except BadName as exc:
        raise AppmodeError(str(exc)) from None
    domain = args.domain if args.domain is not None else _env_domain()
    return _serve(args, domain, *names)


def _serve(args: argparse.Namespace, domain: int, ns: str, node: str) -> int:
    from appmode.host import signals
    from appmode.net.config import close_session, open_session
    from appmode.ros.graph import Node
    from appmode.ros.node import TOPIC_SETS, Options, RosNode
    from appmode.session.hold import HoldToDrive
    from appmode.session.opener import open_session as open_car

    connect = tuple(args.connect or [ROUTER])
    config_file = os.environ.get("ZENOH_SESSION_CONFIG_URI") or None
    router = open_session("router", None, listen=connect) if args.router else None
    zenoh = None
    stack = ExitStack()  # the live view, stopped after the car's stop
    try:
        zenoh = open_session("peer", None, (LISTEN,), connect, config_file=config_file)
        if not list(zenoh.info.routers_zid()):
            raise AppmodeError(
                f"no Zenoh router at {', '.join(connect)}: start one (ros2 run rmw_zenoh_cpp "
                "rmw_zenohd), or add --router to run it here"
            )
        views = stack.enter_context(LiveViews(args.foxglove, args.foxglove_drive))
        choice = board_choice(args, both=True)  # a sim:// board's records give odom
        timeout = args.cmd_vel_timeout
        held = HoldToDrive(first_timeout=timeout, repeat_timeout=timeout)
        session = open_car(choice, held, view=views.make)
        session.lease, session.lease_source = timeout, "cmd_vel"
        graph = Node(domain, ns, node, str(zenoh.zid()), args.distro)
        topics = TOPIC_SETS[args.topics].placed(
            ns, args.frame_prefix or "", args.odom_frame, args.base_frame
        )
        options = Options(args.stamped, timeout, topics)
        ros = RosNode(session, zenoh, graph, options, _log)
        session.on_message = ros.say  # the session's lines: stderr and /rosout
        ended = [False]
        try:
            session.start()
            ros.declare()
            where = ", ".join(connect)
            print(f"ros: node {ns.rstrip('/')}/{node} on domain {domain} via {where}", flush=True)
            with signals.diverted(lambda: ended.__setitem__(0, True)):
                ros.run(lambda: ended[0])
        finally:
            session.close()  # the car's stop, then the node leaves the graph
            ros.withdraw()
            for note in session.closing_notes:
                _log(f"WARNING: {note}")
            if session.undelivered is not None:
                print(f"appmode: {session.undelivered}", file=sys.stderr)
        return 1 if session.left_moving else 0
    finally:
        stack.close()
        if zenoh is not None:
            close_session(zenoh)
        if router is not None:
            close_session(router)


def _env_domain() -> int:
    text = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if not text:
        return 0
    try:
        return _domain(text)
    except argparse.ArgumentTypeError as exc:
        raise AppmodeError(f"ROS_DOMAIN_ID: {exc}") from None


def _add_frames(ros: argparse.ArgumentParser) -> None:
    """The frames the node names, and where its transforms go."""
    ros.add_argument(
        "--odom-frame",
        type=frame_name,
        metavar="FRAME",
        help="odom's frame (default: the topic set's, odom or odom_combined)",
    )
    ros.add_argument(
        "--base-frame",
        type=frame_name,
        metavar="FRAME",
        help="the car's frame (default: the topic set's, base_link or base_footprint)",
    )
    ros.add_argument(
        "--frame-prefix",
        type=frame_name,
        metavar="PREFIX",
        help="put before every frame the node names (car1/: car1/odom, car1/base_link); with "
        "--namespace the transforms go to the namespace's tf (/NS/tf), where a namespaced "
        "Nav2 listens, so that two cars' trees stay apart",
    )


def frame_name(text: str) -> str:
    """A tf frame's name (or prefix): printable, no spaces, not starting with / (tf2)."""
    if not text or not text.isprintable() or " " in text or text.startswith("/"):
        raise argparse.ArgumentTypeError(
            f"{text!r} is no frame name: printable, no spaces, no leading / (e.g. car1/)"
        )
    return text


def _ros_module() -> None:
    try:
        import rosbags  # noqa: F401
        import xxhash  # noqa: F401
    except ImportError:
        raise AppmodeError(f"appmode ros needs rosbags and xxhash: {install_line('ros')}") from None


def _log(text: str) -> None:
    print(f"ros: {text}", file=sys.stderr, flush=True)
