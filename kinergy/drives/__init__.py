"""Drives: transmissions, friction models and the motor's electrical model (motor side)."""

from kinergy.drives.friction import FRICTION_MODELS, check_friction, friction_torque

__all__ = ["FRICTION_MODELS", "check_friction", "friction_torque"]
