"""Run Python with pydrake unimportable: ``python tests/_no_drake.py -c CODE`` or
``python tests/_no_drake.py cli ARGS...`` (the stewart-drake CLI, exit code passed through)."""

import importlib.abc
import sys


class BlockPydrake(importlib.abc.MetaPathFinder):
    """Refuse every ``pydrake`` import, as on a machine without Drake."""

    def find_spec(self, name, path=None, target=None):
        if name == "pydrake" or name.startswith("pydrake."):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, BlockPydrake())

if __name__ == "__main__":
    if sys.argv[1] == "-c":
        exec(compile(sys.argv[2], "<no-drake>", "exec"))
    else:
        from stewart_drake.cli import main

        sys.exit(main(sys.argv[2:]))
