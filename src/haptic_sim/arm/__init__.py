"""Simulated multi-DOF arms (the PHANToM 1.5, any URDF arm): settings, dynamics, contact, the batch
session.
"""
