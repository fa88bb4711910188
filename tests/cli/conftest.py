"""Fixtures of the CLI tests."""

import pytest


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A fresh working directory: the test's ``tmp_path``."""
    monkeypatch.chdir(tmp_path)
    return tmp_path
