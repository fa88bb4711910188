"""Help and progress texts a user reads (issue 24, item 9)."""

import json

import pytest

from stewart_drake.cli import main


def _help(capsys, *argv) -> str:
    try:
        main([*argv, "--help"])
    except SystemExit:
        pass
    return " ".join(capsys.readouterr().out.split())


def test_top_level_help_is_for_users(capsys):
    out = _help(capsys)
    assert "Each subcommand lives" not in out and "commands/<name>.py" not in out
    assert "exit 0: a good result, 1: a result outside physical limits" in out


def test_montecarlo_help_lists_every_key(capsys):
    from stewart_drake.montecarlo.spec import KEYS

    out = _help(capsys, "montecarlo")
    for key in KEYS:
        assert key in out, key


def test_simulate_reports_its_real_time_factor(tmp_path, capsys):
    rc = main(
        ["simulate", "--controller", "float", "--duration", "0.05", "--out", str(tmp_path / "s"), "--no-progress"]
    )
    out, err = capsys.readouterr()
    s = json.loads(out)
    assert rc == 0 and s["real_time_factor"] == pytest.approx(0.05 / s["wall_s"], rel=1e-12)
    assert f"simulated 0.05 s in {s['wall_s']:.3g} s of wall time ({s['real_time_factor']:.3g} × real time)" in err
