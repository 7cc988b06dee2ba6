"""The import's warm-up: the JIT's one-time start-up on a background thread (kernels.parallel.warm_up).

Each case runs in a fresh interpreter, since the warm-up happens once, at ``import reactor``."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _run(script: str, tmp_path, **env) -> dict:
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT,
                                                          REACTOR_CACHE_DIR=str(tmp_path / "cache"), **env))
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.splitlines()[-1])


STATE = '''
    import json, threading
    import numpy as np
    import reactor
    from reactor.kernels import parallel
    started = parallel._warm_up is not None
    parallel._join_warm_up()
    first = parallel.runtime()
    @reactor.kernel
    def f(x: reactor.Float) -> reactor.Float:
        return x * 2.0 + 1.0
    y = f(np.arange(40, dtype=np.float32))
    print(json.dumps({"started": started, "same": parallel.runtime() is first,
                      "ok": bool((y == np.arange(40) * 2 + 1).all()),
                      "threads": sorted(t.name for t in threading.enumerate() if t.name.startswith("reactor"))}))
'''


def test_the_import_starts_the_jit_on_a_thread_and_a_kernel_uses_what_it_made(tmp_path):
    r = _run(STATE, tmp_path)
    assert r == {"started": True, "same": True, "ok": True, "threads": []}  # done, and gone


def test_reactor_warmup_0_starts_nothing(tmp_path):
    r = _run(STATE, tmp_path, REACTOR_WARMUP="0")
    assert r["started"] is False and r["ok"] and r["same"]


def test_a_kernel_built_while_the_warm_up_runs_gets_the_one_runtime(tmp_path):
    # no join: the first build races the thread; the runtime is built once either way
    r = _run('''
        import json
        import numpy as np
        import reactor
        from reactor.kernels import parallel
        @reactor.kernel
        def f(x: reactor.Float) -> reactor.Float:
            return x + 1.0
        y = f(np.ones(100, np.float32))
        parallel._join_warm_up()
        print(json.dumps({"ok": bool((y == 2).all()), "one": len(parallel._runtimes) == 1,
                          "dispatch": parallel.dispatcher() == parallel.runtime().address("reactor_dispatch")}))
    ''', tmp_path)
    assert r == {"ok": True, "one": True, "dispatch": True}


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork")
def test_a_fork_right_after_the_import_runs_kernels_in_the_child(tmp_path):
    r = _run('''
        import json, os
        import numpy as np
        import reactor
        pid = os.fork()  # waits for the warm-up first
        if pid == 0:
            @reactor.kernel
            def f(x: reactor.Float) -> reactor.Float:
                return x * 3.0
            ok = bool((f(np.ones(70000, np.float32)) == 3).all())
            os._exit(0 if ok else 1)
        _, status = os.waitpid(pid, 0)
        print(json.dumps({"child": os.waitstatus_to_exitcode(status)}))
    ''', tmp_path)
    assert r == {"child": 0}


def test_a_distrusted_cache_still_warns_at_the_users_first_build(tmp_path):
    shared = tmp_path / "cache"
    shared.mkdir()
    shared.chmod(0o777)
    r = _run('''
        import json, warnings
        import numpy as np
        import reactor
        from reactor.kernels import parallel
        parallel._join_warm_up()  # the warm-up met the distrusted directory, quietly
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            @reactor.kernel
            def f(x: reactor.Float) -> reactor.Float:
                return x - 1.0
        print(json.dumps([str(w.message) for w in seen]))
    ''', tmp_path)
    assert len(r) == 1 and "writable by" in r[0]
