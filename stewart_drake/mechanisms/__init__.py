"""The two other mechanisms of the source documents: the RC-servo hexapod (seed 002) and the 3R planar leg (seed 003) (numpy)."""
