"""The car as a ROS 2 node with no ROS installed: rmw_zenoh's wire format over Zenoh —
its key expressions and liveliness tokens (`graph`), a sample's attachment and an
entity's GID (`wire`), CDR messages through rosbags (`messages`, dead reckoning from
`protocol.odometry`), and the node (`node`: a cmd_vel is a twist the session drives,
odom the twist it senses)."""
