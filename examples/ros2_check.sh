#!/usr/bin/env bash
# Check `appmode ros` against a real ROS 2 (Jazzy or later, or Humble with
# --distro humble on appmode's side) with rmw_zenoh, and print a report to send back.
# On a machine with ROS 2 and rmw_zenoh installed, with `appmode ros …` running on the
# car's computer and both reaching the same router:
#   source /opt/ros/jazzy/setup.bash && bash ros2_check.sh [NAMESPACE]
# It drives the car forward at 0.1 m/s for two seconds: lift it off the ground first.
set -u
ns="${1:-}"
export RMW_IMPLEMENTATION=rmw_zenoh_cpp
step() { printf '\n== %s\n' "$*"; }
step "ROS: ${ROS_DISTRO:-unknown}, rmw: $RMW_IMPLEMENTATION"
step "ros2 node list (expect ${ns:-}/appmode)"
ros2 node list
step "ros2 topic list -t"
ros2 topic list -t
for topic in odom battery_state imu cmd_vel; do
  step "ros2 topic info -v ${ns}/${topic}"
  ros2 topic info -v "${ns}/${topic}"
done
step "one odom message"
timeout 10 ros2 topic echo --once "${ns}/odom" nav_msgs/msg/Odometry
step "odom's rate (5 s)"
timeout 5 ros2 topic hz "${ns}/odom"
step "cmd_vel forward 0.1 m/s for 2 s, then silence (the car should stop within 0.5 s)"
timeout 2 ros2 topic pub --rate 10 "${ns}/cmd_vel" geometry_msgs/msg/Twist '{linear: {x: 0.1}}'
sleep 1
step "odom's twist after the silence (expect linear.x near 0)"
timeout 10 ros2 topic echo --once --field twist.twist.linear "${ns}/odom"
step "ros2 param list ${ns}/appmode (expect the car's nine)"
timeout 20 ros2 param list "${ns}/appmode"
step "ros2 param describe and get max_speed"
timeout 20 ros2 param describe "${ns}/appmode" max_speed
timeout 20 ros2 param get "${ns}/appmode" max_speed
step "ros2 param set max_speed to what it is (expect: Set parameter successful)"
value=$(timeout 20 ros2 param get --hide-type "${ns}/appmode" max_speed 2>/dev/null)
[ -n "$value" ] && timeout 20 ros2 param set "${ns}/appmode" max_speed "$value"
step "the set's /parameter_events (set it again, then read one)"
(sleep 2; [ -n "$value" ] && timeout 20 ros2 param set "${ns}/appmode" max_speed "$value") &
timeout 15 ros2 topic echo --once /parameter_events rcl_interfaces/msg/ParameterEvent
wait
step "one /rosout line"
timeout 10 ros2 topic echo --once /rosout rcl_interfaces/msg/Log
step "done: please send this output, and whether the car moved and stopped"
