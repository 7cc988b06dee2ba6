"""Hostile SPIR-V: valid modules with random words changed (a bit flipped, a word replaced, an id
off by one), translated without spirv-val (the translator's own checks) and with it. Each either
builds or raises one ReactorError: no other exception, no hang (each case is bounded by an alarm).
More cases: REACTOR_SPIRV_FUZZ=1000."""
import os
import random
import signal

import pytest

import reactor
from reactor.errors import ReactorError

from .test_from_glsl import CONTROL, LOOPS, VECTORS  # noqa: F401 - skips without the glsl extra

CASES = int(os.environ.get("REACTOR_SPIRV_FUZZ", "60"))


def _mutants(seed: int, count: int):
    from reactor.spirv.glsl import compile_glsl

    rng = random.Random(seed)
    modules = [compile_glsl(src) for src in (LOOPS, CONTROL, VECTORS)]
    for _ in range(count):
        spv = bytearray(rng.choice(modules))
        words = len(spv) // 4
        for _ in range(rng.randint(1, 3)):
            w = rng.randrange(5, words)
            old = int.from_bytes(spv[4 * w:4 * w + 4], "little")
            new = rng.choice([rng.getrandbits(32), old ^ (1 << rng.randrange(32)), (old + rng.choice([-1, 1])) % 2**32])
            spv[4 * w:4 * w + 4] = new.to_bytes(4, "little")
        yield bytes(spv)


def _hang(*_):
    raise TimeoutError("a translation did not end in 60 s")


@pytest.mark.parametrize("validate", [False, True], ids=["translator", "spirv-val"])
def test_a_changed_module_builds_or_is_one_clear_error(validate):
    previous = signal.signal(signal.SIGALRM, _hang)
    outcomes = {"built": 0, "refused": 0}
    try:
        for n, spv in enumerate(_mutants(20261128 + validate, CASES if not validate else CASES // 3)):
            signal.alarm(60)
            try:
                reactor.from_spirv(spv, uniforms={"gain": 1.0}, cache=False, name=f"mutant{n}", validate=validate)
                outcomes["built"] += 1
            except ReactorError as exc:
                assert str(exc)
                outcomes["refused"] += 1
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert outcomes["refused"] > 0
