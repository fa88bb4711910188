"""Run Python with pydrake unimportable, as on a machine without Drake.

Three ways in: ``python tests/cli/_no_drake.py -c CODE``, ``python tests/cli/_no_drake.py cli ARGS...`` (the
stewart-drake CLI, exit code passed through), or as a pytest plugin, ``python -m pytest -p tests.cli._no_drake
tests/core ...``: importing this module installs the blocker before pytest collects a test, so every test module
and everything it imports sees no pydrake."""

import importlib.abc
import sys


class BlockPydrake(importlib.abc.MetaPathFinder):
    """Refuse every ``pydrake`` import, as on a machine without Drake."""

    def find_spec(self, name, path=None, target=None):
        if name == "pydrake" or name.startswith("pydrake."):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, BlockPydrake())


def pytest_report_header(config):
    """Say in pytest's header that this run has no pydrake (and whether some import slipped in before)."""
    loaded = sorted(n for n in sys.modules if n == "pydrake" or n.startswith("pydrake."))
    return f"pydrake blocked (tests/cli/_no_drake.py); already imported before the blocker: {loaded or 'none'}"


if __name__ == "__main__":
    if sys.argv[1] == "-c":
        exec(compile(sys.argv[2], "<no-drake>", "exec"))
    else:
        from stewart_drake.cli import main

        sys.exit(main(sys.argv[2:]))
