"""Second and third opinions: the platform in Pinocchio and in MuJoCo.

``models`` writes the engines' model files from a ``Platform`` (text only: URDF of the open tree with the
loop-closure YAML, MJCF), so ``stewart-drake model --format urdf|mjcf`` works without either engine.
``pinocchio_engine`` and ``mujoco_engine`` import their engine at module top (``pip install .[engines]``);
``cross_check`` runs the kinematic and inverse-dynamic comparisons against the closed forms of ``core``.
"""
