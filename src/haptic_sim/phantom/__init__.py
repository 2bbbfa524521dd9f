"""The thesis's PHANToM 1.5 studies on the simulated arm (section 5.2)."""
