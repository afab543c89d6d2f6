"""Robot models as data: dataclasses, robot files (TOML, URDF) and the built-in library."""

from kinergy.model.library import library_names, load_robot
from kinergy.model.robot import (
    CONVENTIONS,
    SOURCE_CATEGORIES,
    SOURCE_STATUSES,
    Drive,
    Friction,
    Joint,
    Limits,
    Link,
    Payload,
    Robot,
    Source,
    Thermal,
    inertia_matrix,
)
from kinergy.model.toml import (
    parse_payload,
    read_robot_file,
    robot_from_dict,
    robot_to_dict,
    save_robot,
)

__all__ = [
    "CONVENTIONS",
    "SOURCE_CATEGORIES",
    "SOURCE_STATUSES",
    "Drive",
    "Friction",
    "Joint",
    "Limits",
    "Link",
    "Payload",
    "Robot",
    "Source",
    "Thermal",
    "inertia_matrix",
    "library_names",
    "load_robot",
    "parse_payload",
    "read_robot_file",
    "robot_from_dict",
    "robot_to_dict",
    "save_robot",
]
