"""Design analysis (numpy, no Drake): actuator sizing along trajectories and over envelopes, Cartesian
stiffness and compliance, natural frequencies, and workspace maps of them. ``design_drake`` checks the
frequencies against Drake's linearisation."""
