"""Build settings: what the user asks for (``BuildOptions``) and what a build uses (``Build``).

``with reactor.options(fma=False, width=8): ...`` changes the defaults for
everything built in the block on this thread; an explicit keyword argument to
``Function``/``kernel`` always wins. When a build starts, its options are
resolved once into an immutable ``Build`` (the target object, the width, FMA,
precision, optimization level, cache use) that is passed to every layer; no
layer re-reads thread-local state or changes it mid-build. Inside a body,
``reactor.fma_mode(...)`` and ``reactor.precision(...)`` give the code of a
block different settings (a new ``Build`` for that block), and
``reactor.build_settings()`` tells the code being emitted which settings it has.
"""
from __future__ import annotations

import contextlib
import dataclasses
import enum
import threading
import typing

from .errors import ReactorError
from .ir.types import WIDTHS
from .targets import Target, get_target


class Precision(str, enum.Enum):
    """How accurate the math built-ins are (Vulkan's names in brackets).

    ``RELAXED``: Vulkan's RelaxedPrecision (mediump) tolerances; ``FULL``: Vulkan's
    full precision (highp) tolerances. Beyond Vulkan (the routines that have them, e.g.
    exp2, log2, pow; others refuse): ``FAITHFUL``, below 1 ULP for every input, and
    ``CORRECT``, correctly rounded for every input; both follow C99 Annex F at special values."""

    RELAXED = "relaxed"
    FULL = "full"
    FAITHFUL = "faithful"
    CORRECT = "correct"

    @classmethod
    def of(cls, value) -> "Precision":
        """``value`` as a Precision (GLSL's ``highp``, ``mediump`` and ``lowp`` too: Vulkan
        treats lowp as mediump); a clear error for anything else."""
        if isinstance(value, str) and value in _GLSL_QUALIFIERS:
            return cls(_GLSL_QUALIFIERS[value])
        try:
            return cls(value)
        except ValueError:
            names = ", ".join(repr(p.value) for p in cls)
            raise ReactorError(f"precision must be one of {names}, not {value!r}") from None

    def __str__(self) -> str:
        return self.value


#: The tiers every math built-in has (Vulkan's), least accurate first: what a shader plans among.
SHADER_TIERS = (Precision.RELAXED.value, Precision.FULL.value)

#: The precision continuum (``routines.continuum``): per routine, its variants below a tier
#: (``"full-d3"``: full's form with a degree-3 polynomial), cheapest first. Registered by the
#: library that builds the routine; a plan's site may name one, as may a call's ``precision=``.
VARIANTS: dict[str, tuple[str, ...]] = {}


def register_variants(routine: str, names: typing.Iterable[str]) -> None:
    """Declare the continuum variants ``routine`` can be built in (``"full-d3"`` ...), cheapest first."""
    for name in names:
        split_precision(name)  # a tier, a dash, the variant
    VARIANTS[routine] = tuple(names)


def split_precision(value, routine: str | None = None) -> tuple[Precision, str | None]:
    """``value`` as (tier, variant): ``"full"`` is (FULL, None), ``"full-d3"`` (FULL, "d3"); with
    ``routine`` (once its library registered it), a variant it does not have is a clear error
    listing those it has."""
    if isinstance(value, str) and "-" in value:
        tier, variant = value.split("-", 1)
        level = Precision.of(tier)
        if routine is not None and routine in VARIANTS and value not in VARIANTS[routine]:
            known = ", ".join(repr(v) for v in VARIANTS.get(routine, ())) or "none"
            raise ReactorError(f"{routine} has no precision variant {value!r}; its variants are {known}")
        return level, variant
    return Precision.of(value), None

_GLSL_QUALIFIERS = {"highp": "full", "mediump": "relaxed", "lowp": "relaxed"}


@dataclasses.dataclass(frozen=True, order=True)
class Site:
    """One routine call site's settings, chosen by a plan (``reactor.plan``): the routine
    ``routine`` emitted from the user's line ``where`` ("file:line", as ``RoutineCall.where``)
    is built at ``precision`` (a tier, or a continuum variant below one: ``"full-d3"``) with FMA
    ``fma`` (None: the build's), whatever the build's or the call's own setting."""

    where: str
    routine: str
    precision: str
    fma: bool | None = None
    #: the operands' ranges a plan proved on an exhaustive domain, ``(lo, hi, nan)`` each (``()``: none
    #: known): the routine may drop the special-case paths they exclude (``routines.continuum``)
    ranges: tuple = ()

    def __post_init__(self):
        level, variant = split_precision(self.precision, self.routine if "-" in str(self.precision) else None)
        object.__setattr__(self, "precision", level.value + (f"-{variant}" if variant else ""))
        try:
            ranges = tuple((float(lo), float(hi), bool(nan)) for lo, hi, nan in (self.ranges or ()))
        except (TypeError, ValueError):
            raise ReactorError(f"Site ranges must be (lo, hi, nan) per operand, not {self.ranges!r}") from None
        object.__setattr__(self, "ranges", ranges)


def _sites(value) -> tuple[Site, ...]:
    """The ``sites`` option as a sorted tuple of Site (from Sites, (where, routine, precision[, fma])
    tuples, or anything with a ``sites`` attribute, such as a Plan)."""
    value = getattr(value, "sites", value)
    try:
        sites = tuple(v if isinstance(v, Site) else Site(*v) for v in value)
    except (TypeError, ValueError) as exc:
        raise ReactorError(f"sites must be Site objects or (where, routine, precision[, fma]) tuples: {exc}") \
            from None
    seen = {(s.where, s.routine) for s in sites}
    if len(seen) != len(sites):
        raise ReactorError("sites: one call site (where, routine) is given two settings")
    return tuple(sorted(sites))


@dataclasses.dataclass(frozen=True)
class BuildOptions:
    """The options a user gives (None: the context's or the target's default).

    fma:       True fuses ``MulAdd`` (an error on a target without FMA: no build calls libm's fmaf);
               False emits a rounded multiply and an add and never a fused instruction; None
               (the default): fused where the target has FMA; "emulate": fused everywhere, in
               software where the target has no FMA (exact, vectorized, ~15 instructions each).
    width:     SIMD width of width-generic code (``SIMD.Float``); None: the
               target's natural width (16 with AVX-512, 8 with AVX2, else 4).
    opt:       LLVM optimization level 0..3 (3: reactor's own pass pipeline), or "llvm-o3"
               (LLVM's full O3 pipeline, for comparison).
    target:    a name from ``reactor.TARGETS`` ("host", "avx512", "avx2", "sse4").
    cache:     use the on-disk object cache.
    precision: the default precision of the math built-ins ("full", "relaxed").
    sites:     per call site settings (``Site``; a ``reactor.plan`` Plan): they win over the
               build's and the call's own precision and FMA at that site.
    """

    fma: bool | str | None = None
    width: int | None = None
    opt: int | str | None = None
    target: str | None = None
    cache: bool | None = None
    precision: str | None = None
    sites: typing.Any = None

    def merged(self, **overrides: typing.Any) -> "BuildOptions":
        given = {k: v for k, v in overrides.items() if v is not None}
        unknown = set(given) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise ReactorError(f"unknown build option(s): {', '.join(sorted(unknown))}")
        return dataclasses.replace(self, **given)

    def _fma(self, target: Target) -> bool:
        """Whether ``MulAdd`` fuses: None follows the target; True needs the target's FMA;
        "emulate" fuses everywhere (exact, vectorized, in software where the target has no FMA)."""
        if self.fma is None:
            return target.has_fma
        if self.fma == "emulate":
            return True
        if self.fma not in (True, False, 0, 1):
            raise ReactorError(f"fma must be True, False, None or 'emulate', not {self.fma!r}")
        if self.fma and not target.has_fma:
            raise ReactorError(f"fma=True: target '{target.name}' ({target.cpu}) has no fused multiply-add "
                               f"instruction; use fma=None (fused where the target has it), fma=False, or "
                               f"fma='emulate' (fused results computed exactly in software, vectorized, slower)")
        return bool(self.fma)

    def resolved(self) -> "Build":
        """The settings of a build with these options (target-dependent defaults filled in)."""
        target = self.target if isinstance(self.target, Target) else get_target(self.target or "host")
        width = self.width if self.width is not None else target.natural_width
        if width not in WIDTHS:
            names = ", ".join(map(str, WIDTHS[:-1])) + f" or {WIDTHS[-1]}"
            raise ReactorError(f"SIMD width must be {names}, not {width!r}")
        opt = 3 if self.opt is None else self.opt
        if opt not in (0, 1, 2, 3, "llvm-o3"):
            raise ReactorError(f"optimization level must be 0..3 or 'llvm-o3', not {opt!r}")
        fma = self._fma(target)
        precision = Precision.of(self.precision or Precision.FULL)
        return Build(target, width, fma, opt, True if self.cache is None else bool(self.cache), precision,
                     _sites(self.sites) if self.sites is not None else ())


@dataclasses.dataclass(frozen=True)
class Build:
    """The resolved settings of one build (immutable; every layer reads this one object)."""

    target: Target
    width: int
    fma: bool
    opt: int | str
    cache: bool
    precision: Precision
    sites: tuple[Site, ...] = ()  # per call site settings (a plan's)

    def replace(self, **changes: typing.Any) -> "Build":
        if "precision" in changes:
            changes["precision"] = Precision.of(changes["precision"])
        return dataclasses.replace(self, **changes)

    def key(self) -> tuple:
        """What distinguishes two builds' code (hashable; the target by its key)."""
        key = (self.target.key(), self.target.name, self.width, self.fma, self.opt, self.precision.value)
        return key + (tuple(dataclasses.astuple(s) for s in self.sites),) if self.sites else key

    def site(self, routine: str, where: str) -> Site | None:
        """The settings chosen for ``routine`` called from ``where`` (None: the build's own)."""
        for s in self.sites:
            if s.routine == routine and s.where == where:
                return s
        return None

    def describe(self) -> str:
        """``target=avx512 width=16 fma=on precision=full`` (fma=emulated where the target has none)."""
        fma = ("on" if self.target.has_fma else "emulated") if self.fma else "off"
        return (f"target={self.target.name} width={self.width} fma={fma} "
                f"precision={self.precision.value}" + (f" sites={len(self.sites)}" if self.sites else ""))


_state = threading.local()


def current_options() -> BuildOptions:
    """The innermost ``options(...)`` context of this thread (not resolved)."""
    stack = getattr(_state, "stack", None)
    return stack[-1] if stack else BuildOptions()


@contextlib.contextmanager
def options(**overrides: typing.Any) -> typing.Iterator[BuildOptions]:
    """Context manager that sets default build options on this thread."""
    if "precision" in overrides and overrides["precision"] is not None:
        overrides["precision"] = Precision.of(overrides["precision"]).value
    stack = getattr(_state, "stack", None)
    if stack is None:
        stack = _state.stack = []
    stack.append(current_options().merged(**overrides))
    try:
        yield stack[-1]
    finally:
        stack.pop()
