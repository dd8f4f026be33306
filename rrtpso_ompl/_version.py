"""The package's version: the one place it is written (pyproject.toml reads it from here), so
that ``rrtpso --version`` reads no installed metadata (importing ``importlib.metadata`` and
scanning the installed distributions costs tens of milliseconds)."""

__version__ = "0.1.0"
