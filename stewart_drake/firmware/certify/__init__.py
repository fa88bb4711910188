"""The firmware certified over a pose box (docs/firmware-certificate.md).

- :mod:`.certificate` ``certify(platform, fmt, box, convention, max_cells, ..., implementation) -> Certificate``
  (per word ``WordRange``: proven range, headroom, impossible/possible/certain; ``error_bound_mm`` per leg;
  ``witness``; ``to_dict()``)
- :mod:`.optimize`    ``optimize(platform, config, box, budget_m, objective) -> OptimizeResult`` (``to_dict()``)
- :mod:`.tick`        ``certify_tick(config, max_error_m, max_speed_mps, max_feedforward_n) -> TickCertificate``
- :mod:`.box`         ``PoseBox``, ``parse_box``, ``workspace_box``
- :mod:`.recipe`      the generated ``sd_ik`` over boxes of pose words (``Model``, ``evaluate``);
  :mod:`.tp17_recipe` the same for the seed's tp17.C; :mod:`.intervals` the interval arithmetic
- :mod:`.search`      the branch and bound; :mod:`.sampling` the sampled side (random + adversarial poses)
"""
