"""What a simulated device gives the loop, and the device node's ROS-free loop: settings, timing,
statistics.
"""
