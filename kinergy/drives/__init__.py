"""Drives: transmissions (coupled joints too), the motors' electrical model, the joints' thermal
model and the DC bus that supplies them (motor side)."""
