"""Design synthesis: from a requirements file to a platform geometry with a proof.

- ``requirements``: the requirements YAML (schema, checks naming file, line and field) into SI ``Requirements``;
- ``families``: the parametrised geometry families (``radial-6-6``, ``utn-3-6``) -> ``Platform``;
- ``evaluate``: one design's metrics (stroke, sizing, frequency, condition, joint angles, leg clearance) through
  the project's per-platform functions, and the search's objectives and constraints;
- ``batch``: the same for a batch of designs at once (designs × poses), what the search runs;
- ``synthesize``: search, pick, prove, and the table of requirements met (``SynthesisResult``);
- ``proof``: the rigorous cover of a pose box (within stroke, above the base): ``proven``/``violated``/``unresolved``;
- ``search``: NSGA-II (pymoo) with batches of evaluations on Dask, resumable, deterministic for a seed;
- ``outputs``: the Pareto table and plot, ``design.yaml`` and ``requirements.json``.
"""
