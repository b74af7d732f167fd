"""The laptop of docs/guide/ros.md's "On the car's computer, with ROS on the laptop", run
in a namespace of its own by tests/ros/test_two_machines.py: a router as `rmw_zenohd`
runs (every interface, port 7447; rmw_zenoh's router config) connected to the car's at
CAR, and a ROS context's session beside it with rmw_zenoh's default session config
(peer, tcp/localhost:7447). It waits for NAMESPACE's node, publishes cmd_vel at 10 Hz for
SECONDS, and prints a JSON line of what it saw: the node's topics and the odom twists."""

from __future__ import annotations

import json
import sys
import time

import zenoh

from tests.ros import peer


def main(car: str, namespace: str, seconds: float) -> None:
    config = zenoh.Config()
    config.insert_json5("mode", '"router"')
    config.insert_json5("connect/endpoints", f'["tcp/{car}:7447"]')  # ZENOH_CONFIG_OVERRIDE
    config.insert_json5("listen/endpoints", '["tcp/[::]:7447"]')  # rmw_zenohd's default
    config.insert_json5("scouting/multicast/enabled", "false")
    router = zenoh.open(config)
    ros = peer.session("tcp/localhost:7447")  # listens on tcp/127.0.0.1:0, as rmw_zenoh's
    try:
        end = time.monotonic() + 30
        found = peer.graph(ros)
        while not any(e.topic == f"{namespace}/cmd_vel" for e in found):
            if time.monotonic() > end:
                print(json.dumps({"topics": sorted(e.topic for e in found)}), flush=True)
                return
            time.sleep(0.2)
            found = peer.graph(ros)
        topics = {e.topic: e for e in found}
        odom = peer.Received()
        listening = ros.declare_subscriber(topics[f"{namespace}/odom"].data_key, odom.on_sample)
        twist = peer.TwistPublisher(ros, topics[f"{namespace}/cmd_vel"])
        start = time.monotonic()
        while time.monotonic() - start < seconds:
            twist.publish(0.3)
            time.sleep(0.1)
        listening.undeclare()
        forward = [m.twist.twist.linear.x for m in odom.messages("nav_msgs/msg/Odometry")]
        print(json.dumps({"topics": sorted(topics), "forward": forward}), flush=True)
    finally:
        ros.close()
        router.close()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]))
