"""Helpers shared by the DSL tests (fixtures live in conftest.py).

A module with a unique name, so that ``from dsl_helpers import ...`` cannot
pick up another directory's ``conftest``.
"""
from fractions import Fraction

import numpy as np

import reactor
from reactor import For, Function, Pointer, vector_type

WIDTHS = (1, 4, 8, 16)


# -- comparing results -----------------------------------------------------------

def assert_bits_equal(got, want, *, signed_zero=True):
    """Bit-exact comparison of float (or any) arrays; NaNs match any NaN."""
    got, want = np.asarray(got), np.asarray(want)
    assert got.dtype == want.dtype, (got.dtype, want.dtype)
    assert got.shape == want.shape, (got.shape, want.shape)
    if got.dtype.kind == "f":
        nan_g, nan_w = np.isnan(got), np.isnan(want)
        bad = np.flatnonzero(nan_g != nan_w)
        assert bad.size == 0, f"NaN mismatch at {bad[:8]}: got {got.flat[bad[:8]]}, want {want.flat[bad[:8]]}"
        ok = ~nan_w
        ints = {4: np.uint32, 8: np.uint64}[got.dtype.itemsize]
        g, w = got[ok].view(ints), want[ok].view(ints)
        if not signed_zero:
            zero = (got[ok] == 0) & (want[ok] == 0)
            g, w = g[~zero], w[~zero]
            # signed zeros are accepted either way
        bad = np.flatnonzero(g != w)
        assert bad.size == 0, (f"{bad.size} mismatches, first at {bad[:8]}: got {got[ok][bad[:8]]}, "
                               f"want {want[ok][bad[:8]]}")
    else:
        bad = np.flatnonzero(got != want)
        assert bad.size == 0, f"mismatch at {bad[:8]}: got {got.flat[bad[:8]]}, want {want.flat[bad[:8]]}"


def fma_f32(a, b, c):
    """Correctly rounded float32 a*b+c, computed exactly with fractions."""
    a, b, c = (np.asarray(v, np.float32) for v in (a, b, c))
    out = np.empty(np.broadcast(a, b, c).shape, np.float32)
    for idx in np.ndindex(out.shape):
        x, y, z = (float(v[idx] if v.ndim else v) for v in (a, b, c))
        if not all(np.isfinite([x, y, z])):
            with np.errstate(all="ignore"):
                out[idx] = np.float32(x) * np.float32(y) + np.float32(z)
            continue
        exact = Fraction(x) * Fraction(y) + Fraction(z)
        out[idx] = round_f32(exact)
    return out


def round_f32(exact: Fraction) -> np.float32:
    """Round an exact rational to the nearest float32, ties to even."""
    with np.errstate(over="ignore"):
        guess = np.float32(float(exact))
    if not np.isfinite(guess):
        return guess
    cands = {guess, np.nextafter(guess, np.float32(np.inf)), np.nextafter(guess, np.float32(-np.inf))}
    cands = [c for c in cands if np.isfinite(c)]
    best = min(cands, key=lambda c: (abs(Fraction(float(c)) - exact), int(np.float32(c).view(np.uint32)) & 1))
    if best == 0 and exact < 0:
        return np.float32(-0.0)
    return np.float32(best)


# -- running many operations in one compiled routine -----------------------------

def run_ops(kind: str, width: int, ops, inputs, out_kind: str | None = None, **options):
    """Apply each of ``ops`` (callables on DSL values) lane-wise to ``inputs``.

    ``inputs`` are 1-D arrays of ``kind``'s dtype whose length is a multiple of
    ``width``. One routine is compiled for all ops: it loops over the vectors,
    loads one ``<kind><width>`` per input, and stores every op's result into row
    k of the output. Returns an array of shape ``(len(ops), n)``.
    """
    out_kind = out_kind or kind
    T = vector_type(kind, width)
    O = vector_type(out_kind, width)
    n = inputs[0].size
    assert n % width == 0 and all(x.size == n for x in inputs)
    nin = len(inputs)

    def compute(ins, out, nvec):
        with For(0, nvec) as i:
            vals = [p[i] for p in ins]
            for k, op in enumerate(ops):  # a build-time loop: every op is emitted inline
                out[nvec * k + i] = op(*vals)

    if nin == 1:
        def body(a, out, nvec):
            compute([a], out, nvec)
    elif nin == 2:
        def body(a, b, out, nvec):
            compute([a, b], out, nvec)
    elif nin == 3:
        def body(a, b, c, out, nvec):
            compute([a, b, c], out, nvec)
    else:
        raise ValueError(nin)
    args = [Pointer[T, "nvec"]] * nin + [Pointer[O], reactor.Int]
    fn = Function(body, args=args, returns=None, name=f"ops_{kind}_{width}", width=width, **options)
    dtype = np.dtype(O.vtype.kind.dtype)
    out = np.zeros((len(ops), n), dtype)
    fn(*[np.ascontiguousarray(x) for x in inputs], out.reshape(-1), n // width)
    return out


def serial(fn, *args, **kw):
    """``fn(*args, **kw)`` with reactor's calls on one thread (the settings restored after)."""
    import reactor
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    try:
        return fn(*args, **kw)
    finally:
        reactor.configure_threads(**saved._asdict())
