"""The nodes' process runtime: declared parameters, CPU pinning, the CPU latency request and
console entry points (ROS-free); ``runtime.ros`` holds spinning, the ROS parameter table and
diagnostics, which need rclpy."""
