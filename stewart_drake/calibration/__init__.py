"""Kinematic calibration (numpy + scipy): the model of a built platform (``model``), what measurements can
identify (``identifiability``), robust identification (``identify``), validation (``validate``), the planning of
measurement poses (``plan``), synthetic measurements (``simulate``), the measurement CSVs (``measurements``) and
the calibrated platform file (``export``)."""
