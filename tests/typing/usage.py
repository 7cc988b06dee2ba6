"""A user's program, type-checked with ``mypy --strict`` by tests/typing/test_mypy.py: every
public name it uses must carry type hints (no untyped calls, no Any leaking into user code)."""
from __future__ import annotations

import numpy as np

import reactor
import routines
from reactor import (
    Abs, All, Any, As, Bool, Elif, Else, Extract, Float, Float4, For, If, Int, Int4, Max, Min, MulAdd,
    Pointer, Precision, Select, Sqrt, ToInt, Value, Variable, While, build_settings, fma_mode, kernel, kernel_of,
)


@kernel
def shade(d: Float, radius: Float) -> Float:
    t = 1.0 - d / radius
    glow = routines.exp2(-8.0 * d * d, precision="relaxed")
    return Select(t > 0.0, MulAdd(t, t * glow, 0.0), 0.0)


@kernel(["float32(float32)", "float64(float64)"])
def halve(x: Value) -> Value:
    return x * 0.5


@reactor.function
def clamp_sum(p: Pointer[Float, "n"], n: Int) -> Float:  # type: ignore[name-defined]
    acc = Variable(Float, 0.0)
    with For(0, n) as i:
        x = p[i]
        with If(x > 1.0):
            acc.set(acc + 1.0)
        with Elif(x < 0.0):
            acc.set(acc + 0.0)
        with Else():
            acc += x
    k = Variable(Int, 0)
    with While(lambda: k < 3):
        k += 1
    return acc


def lanes(v: Value) -> Value:
    m = Min(Max(v, 0.0), 1.0)
    with fma_mode(False), reactor.precision(Precision.RELAXED):
        r = Sqrt(Abs(m)) + routines.pow(m, 2.2) + routines.rsqrt(m + 1.0)
    if build_settings().fma:
        r = r * 1.0
    return Select(Any(r > 0.5) & All(r < 2.0), r, As(Float4, ToInt(r) * 0) if r.width == 4 else r)


four = reactor.Function(lanes, args=[Float4], returns=Float4)
u = routines.jit("pow", precision="full", fma=None)
out: np.ndarray = shade(np.linspace(0, 2, 5, dtype=np.float32), np.float32(1.5))
asm: str = kernel_of(u).assembly
settings: reactor.Build = kernel_of(shade).build
threads: int = reactor.thread_settings().threads
first: Value | None = None
_ = (halve, clamp_sum, four, Extract, Int4, Bool, out, asm, settings, threads, first)
