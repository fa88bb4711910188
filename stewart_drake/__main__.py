"""``python -m stewart_drake ...``: the same command line as ``stewart-drake ...``."""

import sys

from stewart_drake.cli import main

if __name__ == "__main__":
    sys.exit(main())
