"""The runtime parts that need rclpy: the spin loop, the ROS parameter table, diagnostics."""
