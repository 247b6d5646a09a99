"""The one exception family a user sees: a clear message naming the problem
and the way out. The CLI prints it on one line and exits with status 2."""


class PinfeedError(ValueError):
    """Bad input or a missing/corrupt stored file."""
