"""The car as a ROS 2 node (issue 67), checked against rmw_zenoh's design doc."""
