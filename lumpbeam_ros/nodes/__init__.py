"""ROS 2 nodes: parameters, QoS and message conversion around core calls."""
