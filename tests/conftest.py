"""Shared by every test directory: compile into a private object cache, so the suite
neither reads nor fills the user's ~/.cache/reactor (and starts cold in CI)."""
import os

import pytest


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
