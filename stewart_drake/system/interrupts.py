"""Who answers Ctrl-C (SIGINT), in every process of this package, from its first moment.

A terminal's Ctrl-C reaches the whole foreground process group: the command line and every worker it
started. One process answers it, quietly:

- the command line (``stewart-drake ...``, ``python -m stewart_drake[.cli] ...``) while it starts
  (importing numpy and pydrake, parsing its options: ~0.5-1 s): nothing to clean up yet, so an interrupt
  ends it at once with one line and the conventional status 130 (``end_at_once``, installed when this
  package is imported). While its command runs (``unwind``, in ``cli.main``) an interrupt raises
  ``KeyboardInterrupt``, so that the command's cleanup runs (temporaries removed, workers stopped) before
  the same line and status; once the command has returned (the interpreter's exit hooks, e.g. a Dask
  cluster closing) it ends at once again;
- a worker process the command line started (its parent is the process named in
  ``$STEWART_DRAKE_CLI_PID``, which ``processes.mark_cli`` sets): ignores SIGINT, the parent alone stops
  the work (no traceback per worker);
- any other process (a program that imports the library, a test runner, a command line started by
  one): left as Python set it. The parent test, not the variable's presence, makes a worker: a
  command started by a process that once ran ``cli.main`` in-process is a command line, not a worker.

Before Python installs its own handler (the first milliseconds of the interpreter) SIGINT has its
default action: the process ends by the signal, also quietly (a shell reports 130).
"""

# Only modules the interpreter has loaded before it runs any program (``_signal`` is the C module under
# ``signal``, whose import takes milliseconds, enum included): this module runs first and must be instant.
import _signal
import os
import sys

CLI_PID_ENV = "STEWART_DRAKE_CLI_PID"
EXIT_INTERRUPTED = 130  # 128 + SIGINT: what a shell reports for a command ended by Ctrl-C
PROGRAM = "stewart-drake"
MODULES = ("stewart_drake", "stewart_drake.cli")  # python -m MODULE runs the command line
# interpreter options that take the next word as their value (python -W ignore -X dev -m ...)
_OPTIONS_WITH_VALUE = ("-W", "-X", "-Q")


def is_command_line(argv: list[str] | None = None) -> bool:
    """True when ``argv`` (the interpreter's own command line, default ``sys.orig_argv``) runs the
    ``stewart-drake`` script or ``python -m`` one of ``MODULES``; a spawned worker (``python -c ...``) or
    any other program is not."""
    words = list(sys.orig_argv if argv is None else argv)[1:]
    i = 0
    while i < len(words):
        w = words[i]
        if w.startswith("-m"):
            module = w[2:] or (words[i + 1] if i + 1 < len(words) else "")
            return module in MODULES
        if w.startswith("-c"):
            return False
        if w.startswith("-"):
            i += 2 if w in _OPTIONS_WITH_VALUE else 1
            continue
        return os.path.basename(w).removesuffix(".exe") == PROGRAM
    return False


def is_worker() -> bool:
    """True in a process whose parent is the command line that marked itself (``$STEWART_DRAKE_CLI_PID``)."""
    return os.environ.get(CLI_PID_ENV) == str(os.getppid())


def _command_word() -> str:
    """The subcommand on this process's command line ("" if none yet)."""
    return next((" " + a for a in sys.argv[1:] if not a.startswith("-")), "")


def _end_now(signum, frame) -> None:
    """SIGINT outside the command's own work: one line, status 130, nothing else (nothing to clean up)."""
    try:
        os.write(2, f"{PROGRAM}{_command_word()}: interrupted\n".encode())
    except OSError:
        pass
    os._exit(EXIT_INTERRUPTED)


def _set(handler) -> None:
    try:
        _signal.signal(_signal.SIGINT, handler)
    except ValueError:  # not the main thread: the main thread's handler stays
        pass


def end_at_once() -> None:
    """An interrupt ends this process at once, quietly, with status 130 (while nothing needs cleaning up)."""
    _set(_end_now)


def unwind() -> None:
    """From now on an interrupt raises ``KeyboardInterrupt`` (the command's cleanup runs)."""
    _set(_signal.default_int_handler)


def ignore() -> None:
    """This process ignores SIGINT (a worker; or the command line once it is ending)."""
    _set(_signal.SIG_IGN)


def at_import() -> None:
    """Called when this package is first imported: the command line's ``end_at_once`` handler, a worker's
    ``ignore`` (see the module docstring); any other process is left alone."""
    if is_command_line():
        end_at_once()
    elif is_worker():
        ignore()
