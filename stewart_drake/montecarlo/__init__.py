"""Monte Carlo robustness studies of the controller in the loop: ``spec`` (what varies, the ``--vary``
SPEC), ``scenario`` (one run as picklable data and the function that runs it), ``study`` (runs on Dask or
in-process, streamed, resumable), ``summary`` (percentiles, sensitivity, the table and plots), ``sweep``
(grid sweeps on the same machinery) and ``animation`` (a replayed run as Meshcat HTML)."""
