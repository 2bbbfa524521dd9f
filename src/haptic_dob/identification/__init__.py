"""Identification of device models from records: the 1-DOF fit, an arm's friction, an arm's whole
model (its parameters, their consistent fit, the URDF written back, the excitation that shows
them), the filters they share.
"""
