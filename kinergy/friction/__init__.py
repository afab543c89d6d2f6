"""Friction models of a joint drive (motor side) and the registry that names them."""

from kinergy.friction.registry import FRICTION_MODELS, check_friction, friction_torque

__all__ = ["FRICTION_MODELS", "check_friction", "friction_torque"]
