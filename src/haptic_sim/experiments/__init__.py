"""The thesis's experiments (chapters 5-7) and beyond: runs, sweeps, figures and the report."""
