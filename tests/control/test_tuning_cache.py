"""``controller.gains: tune`` tunes a machine once: the gains are kept on disk (``system.results``) under the
package's version and the exact inputs, read back by the next run of the same machine, and tuned again when the
code or any input changes; a failure, an unreadable entry or an unusable cache folder never stands in for a
tuning. (Drake-free: the run that plans with them is tested in ``tests/api/test_tune_cache.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

import stewart_drake.control.tuning as tuning
from stewart_drake.control.gains import ControllerConfig, PidGains
from stewart_drake.control.tuning import LoopSpec, tuned_gains
from stewart_drake.core.geometry import load_platform
from stewart_drake.errors import PhysicalLimitError
from stewart_drake.firmware.certify.box import workspace_box
from stewart_drake.system import results


@pytest.fixture
def tunings(tmp_path, monkeypatch):
    """A fresh cache folder, and the tuner replaced by one that counts its calls and returns gains that differ
    at each call (a result read from the cache is then told apart from one tuned again)."""
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    calls = []

    def tune(platform, config, law, spec, lo, hi):
        calls.append(1)
        return PidGains(kp=1000.0 * len(calls), ki=10.0, kd=5.0, kv=5.0)

    monkeypatch.setattr(tuning, "_tune_for_run", tune)
    return calls


def inputs():
    p = load_platform("utn-dynamic")
    config = ControllerConfig.for_platform(p)
    box = workspace_box(p)
    return p, config, "fixed", LoopSpec.of(config, 0.01, 1e-4, False), box.lo, box.hi


def test_any_input_or_the_code_changed_tunes_again(tunings, monkeypatch):
    p, config, law, spec, lo, hi = inputs()
    assert tuned_gains(p, config, law, spec, lo, hi) == tuned_gains(p, config, law, spec, lo, hi)
    assert len(tunings) == 1
    lo2 = lo.copy()
    lo2[0] = np.nextafter(lo2[0], 0.0)  # the box moved by one ulp
    tuned_gains(p, config, law, spec, lo2, hi)
    tuned_gains(p, config, "float", spec, lo, hi)
    tuned_gains(p, config, law, LoopSpec.of(config, 0.011, 1e-4, False), lo, hi)
    tuned_gains(p.replace(mass=p.mass * (1 + 1e-12)), config, law, spec, lo, hi)  # the plate 1e-12 heavier
    assert len(tunings) == 5
    real = results.package_version()
    monkeypatch.setattr(results, "package_version", lambda: real[::-1])  # an edit of the package
    assert tuned_gains(p, config, law, spec, lo, hi).kp == 6000.0 and len(tunings) == 6


def test_an_unreadable_entry_is_tuned_again_and_rewritten(tunings):
    args = inputs()
    tuned_gains(*args)
    (entry,) = results.folder(tuning.CACHE_KIND).glob("*.pickle")
    entry.write_bytes(b"not a pickle")
    assert tuned_gains(*args).kp == 2000.0 and tuned_gains(*args).kp == 2000.0 and len(tunings) == 2


def test_a_failure_is_not_kept(tmp_path, monkeypatch):
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    calls = []

    def fail(*args):
        calls.append(1)
        raise PhysicalLimitError("no gains meet the margins")

    monkeypatch.setattr(tuning, "_tune_for_run", fail)
    for _ in range(2):
        with pytest.raises(PhysicalLimitError):
            tuned_gains(*inputs())
    assert len(calls) == 2 and not list((tmp_path / "cache").rglob("*.pickle"))


def test_an_unusable_cache_folder_only_costs_the_tuning(tunings, tmp_path, monkeypatch):
    blocked = tmp_path / "a-file"
    blocked.write_text("")
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(blocked / "cache"))  # under a file: cannot be created
    args = inputs()
    assert tuned_gains(*args).kp == 1000.0 and tuned_gains(*args).kp == 2000.0


def test_keys_separate_their_inputs():
    assert results.key(b"ab", b"c") != results.key(b"a", b"bc") != results.key(b"abc")
