"""The numeric core, ROS-free: models, observers, control laws, walls, the cycle and the command's
join.
"""
