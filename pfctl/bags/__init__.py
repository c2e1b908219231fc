"""ROS bag reading and writing (replay, recording), as core value types (DESIGN.md)."""
