"""A kernel's cffi declarations are parsed once per cache: a later process reads the module cffi generated for
them from the cache and starts without the C parser; an entry whose bytes differ from its record is parsed
again, never run."""

import json
import os
import subprocess
import sys

import pytest

# Load the small-linalg kernel in a fresh process: ``library()`` is not None only when its loops, called through
# the declarations, give numpy's bits (its probe), so a wrong declaration module cannot pass as a good one.
SCRIPT = """
import json, sys
from stewart_drake.core import small_linalg
print(json.dumps({"kernel": small_linalg.library() is not None, "parser": "pycparser" in sys.modules}))
"""


def load_kernel(cache):
    env = dict(os.environ, STEWART_DRAKE_CACHE=str(cache))
    p = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_declarations_read_from_the_cache_without_the_parser(tmp_path):
    first = load_kernel(tmp_path)
    if not first["kernel"]:
        pytest.skip("no C compiler here (or the kernel's probe refused it): nothing is loaded through cffi")
    assert first["parser"]  # the first process parses the declarations
    assert len(list(tmp_path.glob("ffi-*.py"))) == 1
    assert load_kernel(tmp_path) == {"kernel": True, "parser": False}


def test_an_altered_declarations_entry_is_parsed_again_not_run(tmp_path):
    if not load_kernel(tmp_path)["kernel"]:
        pytest.skip("no C compiler here (or the kernel's probe refused it): nothing is loaded through cffi")
    (entry,) = tmp_path.glob("ffi-*.py")
    entry.write_text("raise SystemExit('the altered entry ran')\n")
    assert load_kernel(tmp_path) == {"kernel": True, "parser": True}
    assert "SystemExit" not in entry.read_text()  # stored again from the parse
    assert load_kernel(tmp_path) == {"kernel": True, "parser": False}
