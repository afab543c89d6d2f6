"""Drives: transmissions (coupled joints too) and the motor's electrical model (motor side)."""
