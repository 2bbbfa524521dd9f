"""Bilateral teleoperation, ROS-free: the slave's law, the channel between the two sides and its
passivity control.

- ``settings``: what a teleoperation session is set with (architecture, mapping, channel);
- ``passivity``: the time-domain passivity observer and controller of one port of the channel;
- ``delay``: one direction of the channel (delay, jitter, loss, in samples) and its watchdog;
- ``ends``: the master's and the slave's end of the channel (what each side computes per cycle);
- ``slave``: the slave arm's joint impedance tracking a Cartesian point (differential IK).

The batch runner (``haptic_sim.teleop.session``) and the nodes run the same classes.
"""
