"""Teleoperation in batch: configuration, session, stability sweep, results, figures, recorded
bags.
"""
