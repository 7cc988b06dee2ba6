"""The peers our routines are compared with, and their accuracy.

* **NumPy** float32 ufuncs (``np.exp2``, ``np.log2``, ``np.power``, ``np.sin``,
  ``np.arctan2``, ...), which dispatch to the widest SIMD loops the CPU
  supports (AVX-512 where present; NumPy has its own float32 sin/cos, the
  others go to its SIMD or libm loops).
* **glibc libmvec** (``libmvec.so.1``): the x86-64 vector-function ABI
  entry points of the widest level the host runs (:func:`vector_level`):
  16 float32 lanes with AVX-512 (``_ZGVeN16v_exp2f``, ``_ZGVeN16vv_powf``,
  ``_ZGVeN16v_sinf``, ...), 8 with AVX2 (``_ZGVdN8v_exp2f``), else 4 with
  SSE (``_ZGVbN4v_exp2f``): sin, cos, exp, log and pow since glibc 2.22,
  the rest since 2.35; an older glibc's missing symbols make those peers
  absent. They are called from a reactor kernel of that width through
  :class:`reactor.External`, so they run in exactly the loop our kernels run
  in (contiguous loads, one call per vector, masked tail). An entry point
  of a level the CPU lacks is never called (it would stop the process).
* **SLEEF** (Debian's ``libsleef3``, ``libsleef.so.3``): ``Sleef_exp2f16_u10``
  / ``_u35``, ``Sleef_log2f16_u10`` / ``_u35``, ``Sleef_powf16_u10``,
  ``Sleef_fastpowf16_u3500``, ``Sleef_sinf16_u10`` / ``_u35``,
  ``Sleef_fastsinf16_u3500``, ``Sleef_atan2f16_u10``, ... the same way
  (``f8`` and ``f4`` instead of ``f16`` at the AVX2 and SSE levels). The suffix is SLEEF's error
  bound: u10 = 1.0 ULP, u35 = 3.5 ULP, u3500 = 350 ULP, u05 = 0.5001 ULP.
  Where the library is not installed (``apt-get install libsleef3``) these
  peers are reported **absent**, not failed.
* **Intel SVML** (``libsvml.so`` from PyPI's ``intel-cmplr-lib-rt``, the optional extra
  ``pip install reactor[svml]``): its five tiers of exp2, exp, log2, log, pow, invsqrt
  (rsqrt), sin, cos, tan, asin, acos, atan, atan2 (no ``cr``), sinh, cosh and tanh at the host's level (``__svml_exp2f8``, ``__svml_exp2f8_ha``, ``_ep``, ``_br``,
  ``_cr``; ``f16`` with AVX-512, ``f4`` with SSE). Intel documents ``la`` (no suffix) at
  4 ULP, ``ha`` 1 ULP, ``ep`` about half the bits, ``br`` bitwise reproducible (1 ULP),
  ``cr`` correctly rounded. Absent without the package.
* **numba** ``@vectorize`` float32 ufuncs, only where numba is importable
  (absent otherwise).

Each peer gets an accuracy point from the same lab call as our variants
(:func:`routines.lab.evaluate` on the same sample, or the exhaustive sweep),
scored against the full (highp) *and* the relaxed tolerance, so the chart
can place it and the report can say which tolerance it meets. C libraries
follow C99 at special values (``powf(0, 0) = 1``, ``powf(-8, 1/3)`` ...)
where the Vulkan/GLSL definition (and our reference) says NaN: such
differences are counted as special-value mismatches, apart from the
tolerance verdict (see :func:`accuracy_verdict`).
"""
from __future__ import annotations

import dataclasses
import functools
import os
from typing import Callable

import numpy as np

LIBMVEC = "libmvec.so.1"
LIBSLEEF = "libsleef.so.3"
LIBSVML = "libsvml.so"

#: (family, label, symbol or numpy callable, arity, documented accuracy) per function.
_NUMPY = {
    "exp2": (np.exp2, "np.exp2"), "exp": (np.exp, "np.exp"), "log2": (np.log2, "np.log2"),
    "log": (np.log, "np.log"), "pow": (np.power, "np.power"), "sqrt": (np.sqrt, "np.sqrt"),
    "rcp": (np.reciprocal, "np.reciprocal"),
    "sin": (np.sin, "np.sin"), "cos": (np.cos, "np.cos"), "tan": (np.tan, "np.tan"),
    "asin": (np.arcsin, "np.arcsin"), "acos": (np.arccos, "np.arccos"), "atan": (np.arctan, "np.arctan"),
    "atan2": (np.arctan2, "np.arctan2"), "sinh": (np.sinh, "np.sinh"), "cosh": (np.cosh, "np.cosh"),
    "tanh": (np.tanh, "np.tanh"),
}
#: The trigonometric and hyperbolic functions (routines/trig.py); atan2 takes (y, x) everywhere.
TRIG = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
#: The functions libmvec has (C names without the trailing ``f``).
_MVEC = ("exp2", "log2", "pow", "exp", "log") + TRIG
#: SLEEF's entry points per function, as (name, error-bound suffix); ``{w}`` is the lane count.
_SLEEF = {
    "exp2": ["exp2f{w}_u10", "exp2f{w}_u35"],
    "log2": ["log2f{w}_u10", "log2f{w}_u35"],
    "pow": ["powf{w}_u10", "fastpowf{w}_u3500"],
    "exp": ["expf{w}_u10"],
    "log": ["logf{w}_u10", "logf{w}_u35"],
    "sqrt": ["sqrtf{w}_u05", "sqrtf{w}_u35"],
} | {f: [f"{f}f{{w}}_u10", f"{f}f{{w}}_u35"] + ([f"fast{f}f{{w}}_u3500"] if f in ("sin", "cos") else [])
     for f in TRIG}
#: SVML's names (C names without ``f``) and its tiers: (symbol suffix, label, documented accuracy).
_SVML = {"exp2": "exp2", "exp": "exp", "log2": "log2", "log": "log", "pow": "pow", "rsqrt": "invsqrt",
         **{f: f for f in ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")}}
SVML_TIERS = (("", "la", "4 ULP"), ("_ha", "ha", "1 ULP"), ("_ep", "ep", "about 11 bits"),
              ("_br", "br", "1 ULP, bitwise reproducible"), ("_cr", "cr", "correctly rounded"))
_SLEEF_CLAIM = {"u05": "0.5001 ULP", "u10": "1.0 ULP", "u35": "3.5 ULP", "u3500": "350 ULP"}
ARITY = {"pow": 2, "atan2": 2}
#: x86-64 vector-function ABI levels, widest first: (required CPU feature, lanes, ISA letter).
_LEVELS = (("avx512f", 16, "e"), ("avx2", 8, "d"), ("sse2", 4, "b"))


@functools.lru_cache(maxsize=None)
def vector_level() -> tuple[int, str]:
    """``(lanes, ISA letter)`` of the widest vector-function ABI level this CPU runs:
    (16, "e") with AVX-512, (8, "d") with AVX2, else (4, "b"); at most the level
    ``ROUTINES_PEER_LEVEL`` names ("avx2" or "sse4": benchmarks/bench_ladder_levels.py)."""
    import reactor

    features = reactor.get_target("host").feature_set
    below = {"avx2": ("avx512f",), "sse4": ("avx512f", "avx2")}.get(os.environ.get("ROUTINES_PEER_LEVEL", ""), ())
    return next((lanes, isa) for feature, lanes, isa in _LEVELS
                if (feature in features and feature not in below) or lanes == 4)


def mvec_symbol(func: str) -> str:
    """libmvec's entry point for ``func`` at the host's level, e.g. ``_ZGVdN8v_exp2f``."""
    lanes, isa = vector_level()
    return f"_ZGV{isa}N{lanes}{'v' * ARITY.get(func, 1)}_{'pow' if func == 'pow' else func}f"


def sleef_symbols(func: str) -> list[str]:
    """SLEEF's entry points for ``func`` at the host's level, e.g. ``Sleef_exp2f8_u10``."""
    lanes, _ = vector_level()
    return [f"Sleef_{name.format(w=lanes)}" for name in _SLEEF.get(func, ())]


@dataclasses.dataclass
class Peer:
    """One peer implementation of ``func``. ``fn(*args, out=out)`` when present."""

    key: str  # unique, e.g. "sleef exp2 u10"
    func: str
    family: str  # numpy, libmvec, sleef, numba
    label: str  # what it is (symbol or NumPy call)
    claimed: str  # documented accuracy
    fn: Callable | None = None
    reason: str = ""  # why absent

    @property
    def present(self) -> bool:
        return self.fn is not None

    def to_json(self) -> dict:
        return {"key": self.key, "func": self.func, "family": self.family, "label": self.label,
                "claimed": self.claimed, "status": "present" if self.present else "absent",
                "reason": self.reason}


@functools.lru_cache(maxsize=None)
def external_kernel(symbol: str, library: str, arity: int = 1, width: int | None = None):
    """A reactor ufunc calling the vector function ``symbol`` (``width`` float32
    lanes, by default the host's :func:`vector_level`) of ``library`` once per
    vector; None if the library or symbol is missing (the reason is then in
    :func:`missing`)."""
    import reactor
    from reactor import External, Float

    width = width or vector_level()[0]
    vec = reactor.vector_type("Float", width)
    ext = External(symbol, returns=vec, args=(vec,) * arity, library=library)
    if not ext.available:
        return None
    if arity == 1:
        def body(x):
            return ext(x)
    else:
        def body(x, y):
            return ext(x, y)
    body.__doc__ = f"{symbol} from {library} (peer)"
    return reactor.kernel(body, name=f"peer_{symbol}", args=[Float] * arity, returns=Float,
                          width=width)


def missing(symbol: str, library: str) -> str:
    """Why an external peer is absent."""
    import ctypes
    try:
        ctypes.CDLL(library)
    except OSError:
        hint = " (Debian/Ubuntu: apt-get install libsleef3)" if "sleef" in library else ""
        return f"{library} not installed{hint}"
    return f"{library} has no symbol {symbol}"


@functools.lru_cache(maxsize=None)
def svml_library() -> str | None:
    """The path of libsvml.so from the ``intel-cmplr-lib-rt`` wheel (its libintlc loaded
    first), or None where it is not installed."""
    import ctypes
    import os
    import site
    import sys

    for root in [sys.prefix, site.getuserbase()] + site.getsitepackages():
        lib = os.path.join(root, "lib")
        if os.path.exists(os.path.join(lib, LIBSVML)):
            try:
                ctypes.CDLL(os.path.join(lib, "libintlc.so.5"), mode=ctypes.RTLD_GLOBAL)
            except OSError:
                return None
            return os.path.join(lib, LIBSVML)
    return None


def svml_symbols(func: str) -> list[tuple[str, str, str]]:
    """(symbol, tier, documented accuracy) of SVML's entry points for ``func`` at the host's level."""
    if func not in _SVML:
        return []
    lanes, _ = vector_level()
    return [(f"__svml_{_SVML[func]}f{lanes}{suffix}", tier, claim) for suffix, tier, claim in SVML_TIERS]


class _RsqrtNumpy:
    """``1 / np.sqrt(x)`` in two NumPy passes through a scratch array laid out
    like ``out`` (an in-place second pass on the harness's stride-0 views
    would make NumPy copy the overlapping operand)."""

    def __init__(self):
        self._scratch = {}

    def __call__(self, x, out):
        key = (out.shape, out.strides)
        tmp = self._scratch.get(key)
        if tmp is None:
            base = np.empty(out.shape[-1] if out.ndim else 1, np.float32)
            tmp = np.lib.stride_tricks.as_strided(base, out.shape, out.strides) \
                if out.ndim == 2 and out.strides[0] == 0 else np.empty_like(out)
            self._scratch = {key: tmp}
        np.sqrt(x, out=tmp)
        return np.divide(np.float32(1.0), tmp, out=out)


_rsqrt_numpy = _RsqrtNumpy()


@functools.lru_cache(maxsize=None)
def _numba_ufunc(func: str):
    import numba  # noqa: F401 - ImportError means absent

    sig1, sig2 = ["float32(float32)"], ["float32(float32, float32)"]
    bodies = {
        "exp2": (sig1, lambda x: np.exp2(x)), "exp": (sig1, lambda x: np.exp(x)),
        "log2": (sig1, lambda x: np.log2(x)), "log": (sig1, lambda x: np.log(x)),
        "sqrt": (sig1, lambda x: np.sqrt(x)), "rcp": (sig1, lambda x: np.float32(1.0) / x),
        "rsqrt": (sig1, lambda x: np.float32(1.0) / np.sqrt(x)),
        "pow": (sig2, lambda x, y: x ** y),
        "sin": (sig1, lambda x: np.sin(x)), "cos": (sig1, lambda x: np.cos(x)),
        "tan": (sig1, lambda x: np.tan(x)), "asin": (sig1, lambda x: np.arcsin(x)),
        "acos": (sig1, lambda x: np.arccos(x)), "atan": (sig1, lambda x: np.arctan(x)),
        "atan2": (sig2, lambda y, x: np.arctan2(y, x)), "sinh": (sig1, lambda x: np.sinh(x)),
        "cosh": (sig1, lambda x: np.cosh(x)), "tanh": (sig1, lambda x: np.tanh(x)),
    }
    sig, fn = bodies[func]
    return numba.vectorize(sig, nopython=True)(fn)


FAMILIES = ("numpy", "libmvec", "sleef", "svml", "numba")


def peers(functions, libraries: dict | None = None, families=FAMILIES) -> list[Peer]:
    """Every peer of ``functions`` in ``families``, present or absent. ``libraries``
    overrides library names (``{"sleef": "libnothere.so"}`` in the tests)."""
    libs = {"libmvec": LIBMVEC, "sleef": LIBSLEEF} | (libraries or {})
    out = []
    for func in functions:
        out += _peers_of(func, libs, families)
    return out


def _peers_of(func, libs, families) -> list[Peer]:
    out = []
    arity = ARITY.get(func, 1)
    if "numpy" not in families:
        pass
    elif func in _NUMPY:
        ufunc, label = _NUMPY[func]
        out.append(Peer(f"numpy {func}", func, "numpy", label, "not documented", ufunc))
    elif func == "rsqrt":
        out.append(Peer("numpy rsqrt", func, "numpy", "1 / np.sqrt (two passes)",
                        "0.5 + 0.5 ULP (two rounded operations)", _rsqrt_numpy))
    if func in _MVEC and "libmvec" in families:
        sym = mvec_symbol(func)
        k = external_kernel(sym, libs["libmvec"], arity)
        out.append(Peer(f"libmvec {func}", func, "libmvec", sym, "glibc: vector variants <= 4 ULP",
                        k, "" if k is not None else missing(sym, libs["libmvec"])))
    for sym in (sleef_symbols(func) if "sleef" in families else ()):
        suffix = sym.rsplit("_", 1)[1]
        k = external_kernel(sym, libs["sleef"], arity)
        name = f"fast{func}" if "_fast" in sym else func
        out.append(Peer(f"sleef {name} {suffix}", func, "sleef", sym, _SLEEF_CLAIM.get(suffix, suffix),
                        k, "" if k is not None else missing(sym, libs["sleef"])))
    if "svml" in families:
        path = libs.get("svml") or svml_library()
        for sym, tier, claim in svml_symbols(func):
            k = external_kernel(sym, path, arity) if path else None
            why = "" if k is not None else ("intel-cmplr-lib-rt not installed (pip install intel-cmplr-lib-rt)"
                                            if not path else missing(sym, path))
            out.append(Peer(f"svml {func} {tier}", func, "svml", sym, claim, k, why))
    if "numba" in families:
        try:
            fn, reason = _numba_ufunc(func), ""
        except ImportError:
            fn, reason = None, "numba not installed"
        except Exception as exc:  # a numba that fails to compile this body
            fn, reason = None, f"numba failed: {exc}"
        out.append(Peer(f"numba {func}", func, "numba", "numba.vectorize of the NumPy expression",
                        "as NumPy/LLVM libm", fn, reason))
    return out


def as_array_function(fn: Callable) -> Callable:
    """``fn(*args, out=)`` as a float32 array function (for the accuracy lab)."""
    if isinstance(fn, np.ufunc):
        return fn

    def call(*args):
        out = np.empty(np.broadcast(*args).shape, np.float32)
        fn(*args, out=out)
        return out
    return call


def accuracy_verdict(full, relaxed) -> dict:
    """A peer's accuracy class from its two lab results (``SweepResult``).

    ``highp``: no scored input beyond the full tolerance; ``relaxed``: none
    beyond the relaxed one; ``specials``: no special-value mismatch (NaN,
    infinities, signed zeros, as the lab defines them)."""
    return {
        "meets_full_tolerance": full.nonconforming == 0,
        "meets_relaxed_tolerance": relaxed.nonconforming == 0,
        "special_mismatches": full.mismatches,
        "class": ("highp" if full.nonconforming == 0 else
                  "relaxed" if relaxed.nonconforming == 0 else "neither"),
    }
