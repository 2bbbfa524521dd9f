"""The one error type for a problem with the user's input: every tool reports it as one line."""


class InputError(Exception):
    """A problem with the user's input (a file, an argument, a configuration), said in one line."""
