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


@pytest.fixture
def rng():
    return np.random.default_rng(20260611)
