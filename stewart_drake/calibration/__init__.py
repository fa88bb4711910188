"""Kinematic calibration (numpy + scipy): the model of a built platform (``model``: joints, sensor offsets and
gains, targets, the poses' own unknowns), what measurements can identify (``identifiability``: SVD, named
freedoms, the fixing convention, condition and observability indices), robust identification (``identify``),
validation (``validate``), the planning of measurement poses (``plan``), synthetic measurements (``simulate``),
the identification's own Monte Carlo (``montecarlo``), the measurement CSVs (``measurements``), the ``--noise``
SPEC (``noise``), the calibrated platform file (``export``) and its figures (``plots``)."""
