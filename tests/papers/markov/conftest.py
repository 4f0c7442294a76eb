"""Fixtures of the `markov` tests: the tiny configuration and its tables (computed once per session)."""

from __future__ import annotations

import pytest

from .tables import run_all, tiny_config


@pytest.fixture(scope="session")
def markov_cfg():
    return tiny_config()


@pytest.fixture(scope="session")
def markov_tables(markov_cfg, tmp_path_factory):
    return run_all(markov_cfg, tmp_path_factory.mktemp("markov_tables"))
