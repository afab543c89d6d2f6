"""Robot models as data: dataclasses, robot files (TOML, URDF) and the built-in library.

The public names are those of :mod:`~kinergy.model.robot` (the dataclasses),
:mod:`~kinergy.model.toml` (robot files) and :mod:`~kinergy.model.library` (built-in robots),
re-exported here as each module lists them in its ``__all__``.
"""

from kinergy.model import library, robot, toml
from kinergy.model.library import *  # noqa: F403 (re-export: library.__all__)
from kinergy.model.robot import *  # noqa: F403 (re-export: robot.__all__)
from kinergy.model.toml import *  # noqa: F403 (re-export: toml.__all__)

__all__ = [*robot.__all__, *toml.__all__, *library.__all__]
