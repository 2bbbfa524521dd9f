"""The control-side ROS 2 nodes: thin wrappers that convert messages and call the core."""
