"""Design synthesis: from a requirements file to a platform geometry with a proof.

- ``requirements``: the requirements YAML (schema, checks naming file, line and field) into SI ``Requirements``;
- ``families``: the parametrised geometry families (``radial-6-6``, ``utn-3-6``) -> ``Platform``;
- ``evaluate``: one design's metrics (stroke, sizing, frequency, condition) and the search's objectives and
  constraints, vectorised over the box's poses;
- ``proof``: the rigorous cover of a pose box (within stroke, above the base): ``proven``/``violated``/``unresolved``;
- ``search``: NSGA-II (pymoo) with batches of evaluations on Dask, resumable, deterministic for a seed;
- ``outputs``: the Pareto table and plot, ``design.yaml`` and ``requirements.json``.
"""
