"""The car as a ROS 2 node with no ROS installed: rmw_zenoh's wire format over Zenoh —
its key expressions and liveliness tokens (`graph`), a sample's attachment and an
entity's GID (`wire`), CDR messages through rosbags (`messages`, dead reckoning from
`protocol.odometry`), what a `cmd_vel` asks of each port (`command`), and the node
(`node`)."""
