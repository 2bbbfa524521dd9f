"""The simulated 1-DOF slide: the plant with its hand and sensor, the batch session, the vibration-
onset protocol.
"""
