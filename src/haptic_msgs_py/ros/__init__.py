"""The parts of the conventions that need rclpy: QoS profiles, parameter declaration, spinning."""
