"""Energy accounting: what a motion costs per joint and in total, and where the energy goes."""
