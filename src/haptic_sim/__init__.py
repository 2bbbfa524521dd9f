"""haptic_sim: simulated haptic devices (slide, PHANToM), the human hand and the force sensor.

``run_session`` is the batch runner: device, hand, wall, controller and observer in-process with
exactly the node graph's cycle timing (command k from sample k, held over [k, k+1)).
"""

__version__ = "0.1.0"
