"""The in-process command line for the CLI tests: ``cli(capsys, *argv)`` runs ``stewart-drake argv`` through
``cli.main`` and returns ``(exit code, stdout, stderr)``, asserting that no traceback reached stderr."""

from stewart_drake.cli import main


def cli(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err
