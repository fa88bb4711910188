"""The ``stewart-drake`` command line. Each subcommand lives in ``stewart_drake/commands/<name>.py``
and defines ``register(subparsers)``, which adds its parser and sets ``func``; this module finds
them all. Bad input exits with status 2 and one line on stderr, never a traceback."""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from . import __version__, commands
from .errors import StewartError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stewart-drake", description=__doc__.split("\n")[0])
    parser.add_argument("--version", action="version", version=f"stewart-drake {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        if not info.name.startswith("_"):
            importlib.import_module(f"{commands.__name__}.{info.name}").register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (StewartError, ValueError, FileNotFoundError) as e:
        print(f"stewart-drake {args.command}: error: {e}", file=sys.stderr)
        return getattr(e, "exit_code", 2)  # PhysicalLimitError: 1
    except BrokenPipeError:  # e.g. `stewart-drake ... | head`
        sys.stderr.close()
        return 0
    except KeyboardInterrupt:
        print(f"stewart-drake {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
