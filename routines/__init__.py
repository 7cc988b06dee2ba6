"""routines: float32 exp2, log2, pow (and exp, log, rcp, rsqrt, sqrt), sin, cos, tan, asin,
acos, atan, atan2, sinh, cosh and tanh for reactor.

Each routine is a DSL builder usable inside any reactor Function or kernel, in
"full" (Vulkan highp) or "relaxed" (Vulkan mediump / RelaxedPrecision)
precision, with ``fma=None`` following the enclosing build's FMA setting::

    @reactor.kernel
    def gamma(x: Float) -> Float:
        return routines.pow(x, 1 / 2.2, precision="relaxed")

``routines.jit(name, precision, fma, width)`` returns a ready NumPy ufunc.

``NAMES``: the names of every routine ``jit`` builds (exp2, exp, log2, ..., atan2).
"""
from .exponential import exp, exp2
from .kernels import NAMES, jit
from .logarithm import log, log2
from .power import pow  # noqa: A004 - the routine's public name
from .reciprocal import rcp, rsqrt, sqrt
from .trig import acos, asin, atan, atan2, cos, cosh, sin, sinh, tan, tanh

from . import glsl as _glsl  # noqa: E402 - after the routines it is made of
import reactor as _reactor  # noqa: E402

_reactor.set_glsl_builtins(_glsl.BUILTINS)  # what GLSL.std.450 calls in reactor.from_glsl / from_spirv

__version__ = _reactor.__version__  # one distribution (reactor-simd), one version

__all__ = ["exp2", "exp", "log2", "log", "pow", "rcp", "rsqrt", "sqrt", "sin", "cos", "tan", "asin", "acos",
           "atan", "atan2", "sinh", "cosh", "tanh", "jit", "NAMES"]
