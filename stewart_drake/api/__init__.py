"""The public API's implementation (``import stewart_drake as sd`` re-exports it; see ``stewart_drake.__all__``).

One module per concern: ``platform``, ``kinematics`` (ik, fk), ``dynamics``, ``design`` (stiffness, modes),
``sizing``, ``reach`` (workspace), ``simulation`` (the one home of a closed-loop run), ``firmware``. Each function
checks its inputs once (the CLI calls it and prints its result) and returns a result object whose ``to_dict()``
is the command's JSON in SI units. This layer sits above core/control/drake and below the app layer
(commands, analyses, montecarlo, report).
"""
