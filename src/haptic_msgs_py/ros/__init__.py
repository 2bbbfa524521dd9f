"""The parts of the message conventions that need rclpy: QoS profiles, the loop's publishers and
subscriptions, raw (serialized) subscriptions."""
