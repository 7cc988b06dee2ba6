"""Fixtures for the reliability tests (fuzzing, hostile inputs, misuse, threads, memory).

Every session gets its own on-disk object cache, as in tests/dsl. Tests marked
``slow`` (the full 10,000-cycle memory check) run only with REACTOR_SLOW_TESTS=1.
"""
from __future__ import annotations

import os

import numpy as np
import pytest


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: long-running; run with REACTOR_SLOW_TESTS=1")


def pytest_collection_modifyitems(config, items):
    if os.environ.get("REACTOR_SLOW_TESTS") == "1":
        return
    skip = pytest.mark.skip(reason="slow: set REACTOR_SLOW_TESTS=1 to run")
    for item in items:
        if item.get_closest_marker("slow") is not None:
            item.add_marker(skip)


@pytest.fixture(scope="session", autouse=True)
def _private_disk_cache(tmp_path_factory):
    saved = {k: os.environ.get(k) for k in ("REACTOR_CACHE_DIR", "REACTOR_CACHE")}
    os.environ["REACTOR_CACHE_DIR"] = str(tmp_path_factory.mktemp("reactor-cache"))
    os.environ.pop("REACTOR_CACHE", None)
    yield
    for k, v in saved.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


@pytest.fixture
def rng():
    return np.random.default_rng(20260611)
