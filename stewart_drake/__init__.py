"""stewart-drake: model and verify Stewart platforms and their fixed-point controllers with Drake.

The maths core (geometry, rotations, kinematics, ...) is plain numpy and imports no Drake; the
modules that build Drake models and systems import pydrake when they are imported.
"""

import os
import signal

__version__ = "0.1.0"

# A worker process that the command line started (a spawned pool or Dask worker: it imports this package
# first): Ctrl-C reaches the whole process group, and the parent alone stops the work and says so in one
# line. Ignored here, as early as possible, so that a Ctrl-C while the worker starts is no traceback
# (``core.processes``: the parent sets STEWART_DRAKE_CLI_PID; the worker's setup also dies with it).
if os.environ.get("STEWART_DRAKE_CLI_PID", str(os.getpid())) != str(os.getpid()):
    signal.signal(signal.SIGINT, signal.SIG_IGN)
