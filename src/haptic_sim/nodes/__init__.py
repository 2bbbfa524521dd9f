"""The simulated device node."""
