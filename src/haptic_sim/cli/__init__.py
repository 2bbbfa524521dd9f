"""The simulator's console entry points: each a thin shell of argparse around a library function."""
