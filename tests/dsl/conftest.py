"""Shared fixtures for the DSL / JIT / kernel tests (helpers: dsl_helpers.py).

Every test session gets its own on-disk object cache (``REACTOR_CACHE_DIR``
in a temporary directory), so the suite neither reads nor pollutes the
user's ``~/.cache/reactor``.
"""
from __future__ import annotations


import numpy as np
import pytest


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    """A fresh, empty disk cache directory for one test."""
    d = tmp_path / "cache"
    monkeypatch.setenv("REACTOR_CACHE_DIR", str(d))
    monkeypatch.delenv("REACTOR_CACHE", raising=False)
    return d


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)
