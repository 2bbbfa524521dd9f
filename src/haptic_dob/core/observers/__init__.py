"""The observers of the external joint effort: the disturbance observer, the momentum observer, and
the factory that builds either from settings.
"""
