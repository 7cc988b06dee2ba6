"""Shared by every test directory: compile into a private object cache, so the suite
neither reads nor fills the user's ~/.cache/reactor (and starts cold in CI); and Ctrl-C
as Python's default in every process the tests start, even when the suite itself was started
with SIGINT ignored (as a shell's background job is): the interrupt tests need it."""
import os
import signal

import pytest

# a handler (not SIG_IGN) in this process is reset to the default in each program it starts,
# whose Python then turns SIGINT into KeyboardInterrupt
signal.signal(signal.SIGINT, signal.default_int_handler)


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
