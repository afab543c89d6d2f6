"""kinergy's version: the one place it is written (``pyproject.toml`` reads it from here).

A module of its own at the bottom of the layers, so that any layer may say which kinergy wrote a
file without importing the package's public API (``kinergy/__init__.py``).
"""

__all__ = ["__version__"]

__version__ = "0.1.0"
