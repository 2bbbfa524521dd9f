"""The recorder's ROS-free parts: what to record, the bag being written, counts, snapshots.

``settings`` holds its parameters and the bag's name, ``topics`` parses the ``topics`` entries
(type, subscription kind, stamp reader), ``recording`` writes the raw messages into the bag and
counts them (``counts``: received, written, missing stamps, progress), and ``snapshots`` tracks
the nodes whose parameters are asked for; ``drain`` takes what is queued at shutdown.
``haptic_dob.nodes.recorder_node`` wires them to ROS.
"""
