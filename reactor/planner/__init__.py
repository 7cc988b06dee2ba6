"""``reactor.plan``: each routine call site's cheapest tier that leaves a scene's output unchanged.

    plan = reactor.plan(shade, inputs={"x": "unorm8", "k": Range(0.5, 4.0)}, output="unorm8")
    print(plan)                 # per call site: tier, the nearest cheaper point and what it changes, cost
    fast = plan.ufunc           # the planned kernel (the same body, built with plan.sites)
    plan.save("shade.plan.json")
    fast = reactor.Plan.load("shade.plan.json").apply(shade)   # no re-planning; refused if the
                                                               # kernel changed since
``inputs``: a domain per element input (``domains.py``: formats, values, ranges, joint rows)
and the arrays of table and texture parameters; ``output``: what the scene stores
(``outputs.py``). The proof is **exhaustive** when the domain can be enumerated (at most
``max_rows`` rows), else a **sample** sharpened around its riskiest rows and re-checked on a
fresh sample; ``plan.proof`` says which. Each site's operands are measured on the rows run
(``ranges.py``) and bounded over the whole domain by interval arithmetic on the traced IR
(``bounds.py``): a site is built for the range that is proved (measured on an exhaustive check,
bounded on a sample) where that drops a special-case path. How the search goes: ``search.py``. The plan and its
figures as data: ``plan.to_json()``; ``python -m reactor plan FILE.py:NAME`` on the command line.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import linecache
import time
import typing

import numpy as np

from ..build import Site
from ..errors import ReactorError
from .domains import MAX_ROWS, Range, Rows
from .outputs import Output
from .bounds import checked_bounds
from .ranges import site_ranges
from .search import TIERS, Search, _short, reference_sites

__all__ = ["plan", "Plan", "Range", "Rows", "PlanStaleError"]


class PlanStaleError(ReactorError):
    """A saved plan does not fit the kernel any more (its body or a planned line changed)."""


@dataclasses.dataclass
class SiteReport:
    """One call site in a plan."""

    where: str
    routine: str
    tier: str
    below: str | None  # the next cheaper tier (None: the chosen one is the cheapest)
    below_changes: int | None  # outputs changed with this site at ``below`` (the rest as planned)
    below_example: dict | None  # one input row that shows it
    saving: float  # modelled cycles per element saved against the reference at this site alone
    source: str | None = None  # the tier the source sets here (GLSL mediump: relaxed), None: none
    source_changes: int | None = None  # outputs changed with this site at ``source`` alone
    sees: list | None = None  # per operand, its values over the check rows (``ranges.OperandRange.text``)
    in_range: bool = False  # built knowing those ranges (special-case paths they exclude dropped)
    bounds: list | None = None  # per operand, its interval over the whole declared domain (``bounds.py``)

    def text(self) -> str:
        saved = f"{self.saving:+.2f}" if self.saving else "     "
        head = f"{self.routine:<6} {_short(self.where):<22} {self.tier:<10} {saved:>6}"
        if self.below is None:
            line = head + "  (the cheapest tier)"
        else:
            example = ""
            if self.below_example:
                example = "  e.g. " + ", ".join(f"{k}={_fmt(v)}" for k, v in self.below_example.items())
            line = head + f"  {self.below}: changes {self.below_changes:,}{example}"
        if self.sees:
            line += f"\n  {'':<6} {'':<22} sees {', '.join(self.sees)}"
            if self.bounds and self.bounds != self.sees:
                line += f" (bounded over the domain by {', '.join(self.bounds)})"
            line += "; built for that range (special cases dropped)" if self.in_range else ""
        if self.source is not None:
            verdict = "safe: the stored output is the same" if not self.source_changes else \
                f"changes {self.source_changes:,} stored outputs"
            line += f"\n  {'':<6} {'':<22} the source asks {self.source} here: {verdict}"
        return line


@dataclasses.dataclass
class Plan:
    """A kernel's plan: ``sites`` (build option), per-site reports, the proof and the figures."""

    kernel: str
    sites: tuple
    reports: list
    output: typing.Any
    proof: str  # "exhaustive" or "sample"
    checked: int  # rows the final plan was checked on (both samples for a sampled proof)
    domain: str
    fingerprint: str
    cycles: dict  # label -> modelled cycles per element ("plan", "all relaxed", "all full", ...)
    changes: dict  # label -> outputs changed against the reference, on the check rows
    times_ms: dict  # label -> best time of one call on the timing rows (same run)
    timing_rows: int
    seconds: float  # planning time
    builds: int
    machine: str = "host"  # the cost model's table the plan ranked its builds by
    ufunc: typing.Any = dataclasses.field(default=None, repr=False, compare=False)

    # -- reading ------------------------------------------------------------------------
    def __str__(self) -> str:
        lines = [f"plan for {self.kernel}: output {Output(self.output).name}, {self.proof} over {self.domain}",
                 f"  ({self.checked:,} rows checked; {self.builds} builds, {self.seconds:.1f} s)"]
        lines.append(f"  {'site':<6} {'':<22} {'tier':<10} {'saves':>6}  the nearest cheaper point (saves: modelled "
                     f"cycles/element, this site alone)")
        lines += ["  " + r.text() for r in self.reports]
        lines.append(f"  {'build':<14} {'changes':>9} {'cycles/el':>10} {'ms':>9}"
                     + ("" if self.machine == "host" else f"   (cycles modelled for {self.machine})"))
        for label in self.cycles:
            ms = self.times_ms.get(label)
            lines.append(f"  {label:<14} {self.changes.get(label, 0):>9,} {self.cycles[label]:>10.2f} "
                         f"{'' if ms is None else f'{ms:9.3f}'}")
        plan_ms = self.times_ms.get("plan")
        speeds = [f"{self.times_ms[label] / plan_ms:.2f}x the speed of {label}"
                  + (" (the same machine code)" if self.times_ms[label] == plan_ms else "")
                  for label in ("all full", f"all {TIERS[-1]}") if plan_ms and self.times_ms.get(label)]
        if speeds:
            lines.append(f"  plan: {', '.join(speeds)} ({self.timing_rows:,} elements, one thread, median "
                         f"of 41, same run)")
        return "\n".join(lines)

    def to_json(self) -> dict:
        """The plan as data (what ``save`` writes)."""
        data = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "ufunc"}
        data["sites"] = [dataclasses.astuple(s) for s in self.sites]
        data["reports"] = [dataclasses.asdict(r) for r in self.reports]
        return data

    # -- keeping ------------------------------------------------------------------------
    def save(self, path: str) -> None:
        """Write the plan as JSON (``Plan.load`` reads it back)."""
        with open(path, "w") as f:
            json.dump(self.to_json(), f, indent=1, default=_plain)

    @classmethod
    def load(cls, path: str) -> "Plan":
        with open(path) as f:
            data = json.load(f)
        data["sites"] = tuple(Site(*s) for s in data["sites"])
        data["reports"] = [SiteReport(**r) for r in data["reports"]]
        return cls(**data)

    def apply(self, ufunc):
        """The kernel ``ufunc`` built with this plan's sites, after checking that the plan was
        made for it as it is now (same reference code, same source at every planned line);
        ``PlanStaleError`` otherwise (plan again)."""
        from ..kernels.kernel import kernel_of
        from ..kernels.kernel import build_kernel
        k = kernel_of(ufunc)
        reference = _rebuild(k, build_kernel, reference_sites(k), TIERS[-1])
        now = fingerprint(kernel_of(reference), self.sites)
        if now != self.fingerprint:
            raise PlanStaleError(f"the plan for '{self.kernel}' was made for other code: the kernel or a "
                                 f"planned line changed since; run reactor.plan again")
        self.ufunc = _rebuild(k, build_kernel, self.sites, TIERS[-1])
        return self.ufunc


def plan(ufunc, inputs: dict, output: typing.Any = "unorm8", *, samples: int = 1 << 18, seed: int = 0,
         max_rows: int = MAX_ROWS, timing_rows: int = 1 << 20, fma: bool | None = None,
         progress: bool = False, machine: str | None = None) -> Plan:
    """Plan the routine call sites of the reactor kernel ``ufunc`` (see the module docstring).

    ``samples``: rows of a sampled check; ``max_rows``: the largest domain checked exhaustively;
    ``timing_rows``: elements each build is timed on (the check rows, repeated); ``fma``: the
    FMA setting of every build (None: the kernel's); ``machine``: the cost model's table the
    builds are ranked by (``reactor.cost``: "zen3", "skylake-x" ...; None: this host's), to plan
    for the CPU a kernel built for another ``target`` will run on (the times stay this host's)."""
    from ..kernels.kernel import kernel_of
    t0 = time.perf_counter()
    log = print if progress else None
    if machine is not None:
        from ..cost.model import MACHINES, machine_for
        if not machine_for(machine).known:
            raise ReactorError(f"plan: no cost table for machine {machine!r}; the tables are "
                               f"{', '.join(k for k in MACHINES if k != 'generic')} (or an LLVM CPU name)")
    search = Search(ufunc, dict(inputs), output, samples=samples, seed=seed, max_rows=max_rows, fma=fma, log=log,
                    machine=machine)
    search.sharpen()
    alone = search.alone()
    sites, best = search.together(alone)
    seen = site_ranges(search)  # what each site's operands are, over the check rows
    proved, unsound = checked_bounds(search, seen)  # ... and can be, over the whole declared domain
    for where, routine in unsound:
        search.log(f"  {routine} at {where}: its interval bound misses values the rows reached; not used")
    spans = {k: tuple(r.widened() for r in v) for k, v in seen.items()} if search.check.exhaustive else proved
    sites, best = search.restrict(sites, best, spans)
    proof = "exhaustive" if search.check.exhaustive else "sample"
    checked = search.check.size
    if search.fresh is not None:  # a sampled plan is re-checked on rows it was not chosen on
        fresh_ref = search.run(search.reference.ufunc, search.fresh)
        again = search.compare(best, search.fresh, fresh_ref)
        checked += search.fresh.size
        if again.changed:
            raise ReactorError(f"plan for '{search.kernel.name}': the chosen sites change {again.changed} outputs "
                               f"on a fresh sample (e.g. {again.example}); declare the domain more closely or "
                               f"sample more (samples=)")
    below = search.below(sites, alone)
    reports = []
    chosen = {(s.where, s.routine): s.precision for s in sites}
    for where, routine in search.sites:
        alone_rows = alone.get((where, routine), [])
        tier = chosen.get((where, routine), TIERS[-1])
        saved = [search.reference.cycles - c.cycles for t, c in alone_rows if t == tier]
        b = below.get((where, routine))
        source = search.authored.get((where, routine))
        source_changes = None if source is None else 0 if source == TIERS[-1] else \
            next((c.changed for t, c in alone_rows if t == source), None)
        ranged = any(x.ranges for x in sites if (x.where, x.routine) == (where, routine))
        reports.append(SiteReport(where, routine, tier, b[0] if b else None, b[1].changed if b else None,
                                  b[1].example if b else None, saved[0] if saved else 0.0, source, source_changes,
                                  [r.text() for r in seen.get((where, routine), ())], ranged,
                                  [r.text() for r in proved.get((where, routine), ())] or None))
    written = search.as_written()
    sites = search.pinned(sites)
    cycles, changes, ufuncs = {}, {}, {}
    for tier in TIERS:
        cand = search.reference if tier == TIERS[-1] else search.compare(search.build((), tier))
        label = f"all {tier}"
        cycles[label], changes[label], ufuncs[label] = cand.cycles, max(cand.changed, 0), cand.ufunc
    if written is not None:
        cycles["as written"], changes["as written"], ufuncs["as written"] = \
            written.cycles, written.changed, written.ufunc
    cycles["plan"], changes["plan"], ufuncs["plan"] = best.cycles, best.changed, best.ufunc
    times = _time(search, ufuncs, timing_rows)
    result = Plan(search.kernel.name, sites, reports, output if not isinstance(output, Output) else output.spec,
                  proof, checked, search.check.description, fingerprint(kernel_of(search.reference.ufunc), sites),
                  cycles, changes, times, timing_rows, 0.0, search.builds, machine or "host")
    result.ufunc = best.ufunc
    result.seconds = time.perf_counter() - t0
    return result


def fingerprint(reference_kernel, sites) -> str:
    """What a plan was made for: the reference build's code (its IR key) and the source text of
    every planned line."""
    h = hashlib.sha256(reference_kernel.code.key.encode())
    for s in sites:
        path, _, line = s.where.rpartition(":")
        h.update(f"{s.where}\0{s.routine}\0{linecache.getline(path, int(line or 0)).strip()}\0".encode())
    return h.hexdigest()


def _rebuild(k, build_kernel, sites, precision):
    b = k.build
    return build_kernel(k.body, name=k.name, args=list(k.signature.params), returns=k.signature.returns, fma=b.fma,
                        width=b.width, opt=b.opt, target=b.target.name, cache=b.cache, precision=precision,
                        sites=sites)


_SLACK = 4096  # elements of room for the timed calls' output offsets (multiples of 16: 64 bytes for float32)


def _time(search: Search, ufuncs: dict, rows: int, repeats: int = 41) -> dict:
    """Median time (ms) of one call of each distinct build on ``rows`` elements (the check rows
    repeated), on one thread, the builds interleaved in every round (same run); labels whose builds
    are the same machine code share one time (a plan that lowers nothing is not "faster"). Each
    call writes into memory allocated once, at an offset drawn per call: a fresh array per call
    would time the allocator's page faults, and one fixed array a fixed placement against the
    inputs (a store stream 4 KiB apart from a load stream slows every call of that one build)."""
    from ..kernels.kernel import kernel_of
    from ..kernels.parallel import configure, settings

    check = search.check
    reps = max(1, -(-rows // check.size))
    columns = {n: np.concatenate([v] * reps)[:rows] for n, v in check.columns.items()}
    args = search.arguments(columns)
    code = {label: kernel_of(u).code.key for label, u in ufuncs.items()}
    distinct = {code[label]: u for label, u in ufuncs.items()}
    samples: dict = {key: [] for key in distinct}
    saved = settings()
    configure(threads=1)  # the machine's other core is someone else's noise
    try:
        with np.errstate(all="ignore"):
            spans = {}
            for key, u in distinct.items():  # warm, and the memory every timed call writes into
                got = u(*args)
                spans[key] = [np.empty((len(g) + _SLACK,) + g.shape[1:], g.dtype)
                              for g in (got if isinstance(got, tuple) else (got,))]
            rng = np.random.default_rng(0)
            for _ in range(repeats):
                for key, u in distinct.items():
                    out = tuple(b[o:o + len(b) - _SLACK] for b in spans[key]
                                for o in [int(rng.integers(0, _SLACK // 16)) * 16])
                    t0 = time.perf_counter()
                    u(*args, out=out)
                    samples[key].append(time.perf_counter() - t0)
    finally:
        configure(threads=saved[0], threshold=saved[1])
    return {label: float(np.median(samples[code[label]])) * 1e3 for label in ufuncs}


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.9g}"
    if isinstance(v, list):
        return "(" + ", ".join(_fmt(x) for x in v) + ")"
    return repr(v)


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON: {value!r}")


