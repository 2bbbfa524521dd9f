"""Identification of device models from records: the 1-DOF fit, an arm's friction, the filters they
share.
"""
