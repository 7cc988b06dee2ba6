"""The search: the cheapest tier per routine call site that leaves the scene's output unchanged.

A site's choices are its routine's ``ladder``: relaxed, the precision continuum's variants
(``routines.continuum``: full's form with polynomials of lower degree, ``full-d3``), full,
faithful and correct. "Tier" below means any point of it.

1. **Reference**: the kernel built with every routine at the most accurate tier (the last of
   ``reactor.Precision``: correctly rounded), run on the check rows (``domains.py``); its stored output
   (``outputs.py``) is what every candidate must reproduce exactly.
2. **Sites**: the routine calls the reference build recorded (``kernel_of(u).routines``: routine
   and the user's file:line; a built-in such as ``normalize`` counts through the routine it calls).
3. **Alone**: each site at each cheaper tier, the others at the reference's: the outputs it
   changes, and its modelled cost (cycles per element, from the dataflow model, ``reactor.cost``).
4. **Together**: every site starts at its least accurate tier from full up that changed nothing
   alone (if that combination changes nothing), then sites are lowered one by one below it, the
   largest saving first, each to its cheapest harmless point (by modelled cost), kept only if the
   combination still changes nothing (two harmless changes can add up to a changed code); else
   its next cheapest harmless points are tried.
5. **Sample domains**: when the check is a sample, the rows whose reference output is closest to
   a rounding boundary are searched around (neighbouring float32 inputs, ``_neighbours``) and added
   to the check before step 3, and the final plan is checked on a second, fresh sample.
6. **The tier below**: for every site not at the cheapest tier, the plan with that site one tier
   lower: how many outputs it changes and one input that shows it.
"""
from __future__ import annotations

import hashlib
import time
import typing

import numpy as np

from ..build import VARIANTS, Precision, Site
from ..cost.model import kernel_cycles
from ..errors import ReactorError
from .domains import Check, hulls, rows_to_check
from .outputs import Output, changed_rows, row_margin

#: least to most accurate: Vulkan's relaxed and full, then faithful and correct, which every routine
#: has (a routine without a tier would be skipped at it); the reference is the last
TIERS = tuple(p.value for p in Precision)


def ladder(routine: str) -> tuple[str, ...]:
    """What a site of ``routine`` may be built at, least accurate first: relaxed, the continuum's
    variants between relaxed and full (``routines.continuum``: ``full-d3`` ...), then the tiers."""
    return (TIERS[0], *VARIANTS.get(routine, ()), *TIERS[1:])
WORST_ROWS = 2048  # rows around which a sampled check searches
NEIGHBOURS = 16  # float32 steps on each side of each of them
TRIES = 3  # harmless points a site tries, cheapest first, beside the sites lowered before it


class Candidate(typing.NamedTuple):
    """One build the search made: its sites, the ufunc, modelled cycles/element and changes."""

    sites: tuple
    ufunc: typing.Any
    cycles: float
    changed: int
    example: dict | None


class Search:
    """The state of one planning run (see the module docstring)."""

    def __init__(self, ufunc, inputs: dict, output, *, samples: int, seed: int, max_rows: int,
                 fma: bool | None, log: typing.Callable[[str], None] | None, machine: str | None = None):
        from ..kernels.kernel import kernel_of
        self.kernel = kernel_of(ufunc)
        self.machine = machine
        self.log = log or (lambda text: None)
        self.output = output if isinstance(output, Output) else Output(output)
        names = list(self.kernel.signature.names)
        ops = self.kernel.ins
        self.element_names = [n for n, o in zip(names, ops) if not o.uniform]
        self.fixed = {n: inputs[n] for n, o in zip(names, ops) if o.uniform and n in inputs}
        missing = [n for n, o in zip(names, ops) if o.uniform and n not in inputs]
        if missing:
            raise ReactorError(f"plan: give the arrays of {', '.join(missing)} in inputs= (tables and textures "
                               f"are passed as they are)")
        self.names = names
        declared = {k: v for k, v in inputs.items() if k not in self.fixed}
        self.declared = declared
        for n, o in zip(names, ops):
            if o.channels > 1 and not o.uniform and n in declared:
                raise ReactorError(f"plan: input '{n}' has {o.channels} channels per element: give its values "
                                   f"as rows, inputs={{'rows': Rows({n}=array of shape (N, {o.channels}), ...)}}")
        self.dtypes = {n: o.dtype for n, o in zip(names, ops) if not o.uniform}
        self.check = self._typed(rows_to_check(self.element_names, declared, samples, seed, max_rows))
        self.fresh = None if self.check.exhaustive else \
            self._typed(rows_to_check(self.element_names, declared, samples, seed + 1, max_rows))
        self.fma = fma
        self.builds = 0
        self.build_seconds = 0.0
        self.top = TIERS[-1]
        #: the sites whose tier the source itself sets (GLSL's mediump, ``precision=`` at a call):
        #: every build pins them (the reference at the top tier), so they are planned like the rest
        self.authored = authored(self.kernel)
        self.reference = self.build((), self.top)
        self.ref_out = self.run(self.reference.ufunc, self.check)
        self.sites = [(c.where, c.name) for c in self.kernel_of(self.reference.ufunc).routines if c.where]

    # -- builds and runs ------------------------------------------------------------------
    @staticmethod
    def kernel_of(ufunc):
        from ..kernels.kernel import kernel_of
        return kernel_of(ufunc)

    def build(self, sites: tuple, precision: str) -> Candidate:
        """The kernel with ``sites`` (Site objects) and every other routine at ``precision``, the
        sites the source sets included."""
        from ..kernels.kernel import build_kernel
        k = self.kernel
        b = k.build
        given = {(s.where, s.routine) for s in sites}
        sites = tuple(sites) + tuple(Site(w, r, precision, self.fma) for w, r in self.authored if (w, r) not in given)
        t0 = time.perf_counter()
        ufunc = build_kernel(k.body, name=k.name, args=list(k.signature.params), returns=k.signature.returns,
                             fma=b.fma if self.fma is None else self.fma, width=b.width, opt=b.opt,
                             target=b.target.name, cache=b.cache, precision=precision, sites=sites)
        self.build_seconds += time.perf_counter() - t0
        self.builds += 1
        return Candidate(tuple(sites), ufunc, cycles_per_element(self.kernel_of(ufunc), self.machine), -1, None)

    def _typed(self, check: Check) -> Check:
        """The check's columns in the kernel's input dtypes (the values a scene passes)."""
        check.columns = {n: np.asarray(v).astype(self.dtypes[n], copy=False) for n, v in check.columns.items()}
        return check

    def arguments(self, columns: dict) -> list:
        return [columns[n] if n in columns else self.fixed[n] for n in self.names]

    def run(self, ufunc, check: Check) -> tuple:
        with np.errstate(all="ignore"):
            out = ufunc(*self.arguments(check.columns))
        return out if isinstance(out, tuple) else (out,)

    def compare(self, candidate: Candidate, check: Check | None = None, reference=None) -> Candidate:
        """``candidate`` with the number of check rows whose output changed, and the first one."""
        check = check or self.check
        reference = reference if reference is not None else self.ref_out
        rows = changed_rows(self.output, reference, self.run(candidate.ufunc, check))
        count = int(rows.sum())
        example = None
        if count:
            i = int(np.flatnonzero(rows)[0])
            example = {n: _plain(v[i]) for n, v in check.columns.items()}
        return candidate._replace(changed=count, example=example)

    # -- the search -----------------------------------------------------------------------
    def sharpen(self) -> None:
        """For a sampled check: add the neighbours of the rows nearest a rounding boundary."""
        if self.check.exhaustive:
            return
        margin = row_margin(self.output, self.ref_out)
        worst = np.argsort(margin, kind="stable")[:WORST_ROWS]
        extra = _neighbours(self.check.take(worst), self.element_names, NEIGHBOURS,
                            hulls(self.element_names, self.declared))
        columns = {k: np.concatenate([v, extra[k]]) for k, v in self.check.columns.items()}
        self.check = Check(columns, False, self.check.description + f" + {len(extra[self.element_names[0]]):,} "
                           f"neighbours of the {len(worst):,} rows nearest a rounding boundary")
        self.ref_out = self.run(self.reference.ufunc, self.check)

    def alone(self) -> dict:
        """Per site: [(tier, Candidate)] for each tier and continuum variant below the reference's
        (``ladder``), least accurate first."""
        found = {}
        for where, routine in self.sites:
            rows = []
            for tier in ladder(routine)[:-1]:
                try:
                    cand = self.build((Site(where, routine, tier, self.fma),), self.top)
                except ReactorError as exc:  # a routine without that tier
                    self.log(f"  {routine} at {_short(where)}: no {tier} ({exc})")
                    continue
                rows.append((tier, self.compare(cand)))
                self.log(f"  {routine} at {_short(where)} {tier}: changes {rows[-1][1].changed:,}, "
                         f"{rows[-1][1].cycles:.2f} cycles/element")
            found[(where, routine)] = rows
        return found

    def as_written(self) -> Candidate | None:
        """The kernel with the tiers its source sets (None where it sets none), compared."""
        if not self.authored:
            return None
        return self.compare(self.build(tuple(Site(w, r, t, self.fma) for (w, r), t in self.authored.items()),
                                       self.top))

    def pinned(self, sites: tuple) -> tuple:
        """``sites`` with the source's own sites that it leaves out at the top tier (a plan
        rebuilt from its sites must not fall back to the source's tier)."""
        given = {(s.where, s.routine) for s in sites}
        return tuple(sorted(tuple(sites) + tuple(Site(w, r, self.top, self.fma) for w, r in self.authored
                                                 if (w, r) not in given)))

    def together(self, alone: dict) -> tuple[tuple, Candidate]:
        """The plan: every site first at its least accurate tier from full up that changed nothing
        alone (full where full is enough: the savings of the tiers), if that combination changes
        nothing (else every site at the reference); then the sites are lowered one by one below
        that, the largest saving first, each to its cheapest harmless point (by modelled cost),
        kept only if the combination still changes nothing (two harmless changes can add up to a
        changed code); a site whose point fails beside the others tries its next ones (``TRIES``),
        then the dearest of those below its start."""
        base = {}
        for site, rows in alone.items():
            upper = [tier for tier, cand in rows if cand.changed == 0 and tier in TIERS[1:]]
            if upper:
                base[site] = upper[0]
        chosen: dict = {}
        best = self.reference._replace(changed=0)
        if base:
            cand = self.compare(self.build(_site_tuple(base, self.fma), self.top))
            self.log(f"  every site from full up: changes {cand.changed:,}, {cand.cycles:.2f} cycles/element")
            if cand.changed == 0:
                chosen, best = dict(base), cand
        options = []
        for site, rows in alone.items():
            cycles = {tier: cand.cycles for tier, cand in rows}
            start = cycles.get(chosen.get(site), self.reference.cycles)
            lower = sorted((cand.cycles, i, tier) for i, (tier, cand) in enumerate(rows)
                           if cand.changed == 0 and cand.cycles < start)
            if lower:  # cheapest first (the least accurate of equals)
                options.append((start - lower[0][0], site, [t for _, _, t in lower]))
        for _, (where, routine), tiers in sorted(options, key=lambda o: -o[0]):
            # the cheapest few, then the dearest (the nearest below its start): the likeliest to hold
            for tier in tiers[:TRIES] + tiers[TRIES:][-1:]:
                trial = dict(chosen)
                trial[(where, routine)] = tier
                cand = self.compare(self.build(_site_tuple(trial, self.fma), self.top))
                self.log(f"  + {routine} at {_short(where)} {tier}: changes {cand.changed:,}, "
                         f"{cand.cycles:.2f} cycles/element")
                # kept only if it changes the machine code (where a tier is the same code on this target,
                # e.g. rsqrt without AVX-512's estimate, lowering it would claim a saving there is not)
                if cand.changed == 0 and cand.cycles <= best.cycles + 1e-9:
                    if _code(cand) != _code(best):
                        chosen, best = trial, cand
                    break
        return _site_tuple({k: v for k, v in chosen.items() if v != self.top}, self.fma), best

    def restrict(self, sites: tuple, best: Candidate, ranges: dict) -> tuple[tuple, Candidate]:
        """Each site at relaxed, full or a point of the continuum, built knowing the ranges its
        operands are proved to lie in (``ranges``: per site, ``ranges.OperandRange`` each: measured
        over an exhaustive check, ``ranges.site_ranges``, or bounded over the declared domain,
        ``bounds.site_bounds``), so that it drops the special-case paths they exclude (exp2's
        subnormal and overflow paths, log2's general one, pow's NaN select, the Newton step's NaN
        select of rsqrt and rcp, relaxed sqrt's zero and infinity select); kept where it changes
        nothing and is cheaper code."""
        current = {(s.where, s.routine): s for s in sites}
        for where, routine in self.sites:
            site = current.get((where, routine))
            tier = site.precision if site is not None else self.top
            spans = ranges.get((where, routine))
            if not (tier in ("relaxed", "full") or tier.startswith("full-")) or not spans or \
                    not all(r.known and r.seen for r in spans) or all(r.unbounded for r in spans):
                continue
            trial = dict(current)
            trial[(where, routine)] = Site(where, routine, tier, self.fma,
                                           tuple((r.lo, r.hi, r.nan) for r in spans))
            cand = self.compare(self.build(tuple(sorted(trial.values())), self.top))
            self.log(f"  {routine} at {_short(where)} {tier} in its range: changes {cand.changed:,}, "
                     f"{cand.cycles:.2f} cycles/element")
            if cand.changed == 0 and cand.cycles <= best.cycles + 1e-9 and _code(cand) != _code(best):
                current, best = trial, cand
        return tuple(sorted(current.values())), best

    def below(self, sites: tuple, alone: dict) -> dict:
        """For each site: the plan with it at the nearest cheaper point of its ladder (by the
        modelled cost each point had alone: the dearest of those cheaper than its own), compared;
        None where no point is cheaper. The search took the cheapest harmless point, so this one
        changes outputs (alone, or beside the other sites) unless the model ranks it only alone."""
        chosen = {(s.where, s.routine): s.precision for s in sites}
        report: dict[tuple, tuple[str, Candidate] | None] = {}
        for where, routine in self.sites:
            tier = chosen.get((where, routine), self.top)
            cycles = {t: cand.cycles for t, cand in alone.get((where, routine), [])}
            own = cycles.get(tier, self.reference.cycles)
            steps = ladder(routine)
            cheaper = sorted((c, -steps.index(t), t) for t, c in cycles.items() if c < own - 1e-9)
            if not cheaper:
                report[(where, routine)] = None
                continue
            lower = cheaper[-1][2]
            trial = dict(chosen)
            trial[(where, routine)] = lower
            try:
                report[(where, routine)] = (lower, self.compare(self.build(_site_tuple(trial, self.fma), self.top)))
            except ReactorError:
                report[(where, routine)] = None
        return report

def authored(kernel) -> dict:
    """{(where, routine): tier} of the call sites whose tier the kernel's source sets itself."""
    default = kernel.build.precision.value
    return {(c.where, c.name): c.precision for c in kernel.routines if c.where and c.precision != default}


def reference_sites(kernel) -> tuple:
    """The sites that make ``kernel``'s reference build: its source's own, at the top tier."""
    return tuple(sorted(Site(w, r, TIERS[-1]) for w, r in authored(kernel)))


def _code(cand) -> str:
    """The key of a candidate build's machine code."""
    from ..kernels.kernel import kernel_of
    return kernel_of(cand.ufunc).code.key


_cycles: dict[str, float] = {}


def cycles_per_element(kern, machine: str | None = None) -> float:
    """The dataflow model's cycles per element of a kernel's vector loop on ``machine``'s table
    (``reactor.cost``; None: the host's). Kept in memory and in the disk cache under the machine
    code's key, the table and reactor's sources (the model reads the optimized IR, which a kernel
    from a cache would otherwise trace and optimize again: nearly all of a re-plan's time)."""
    from ..jit import cache
    from ..kernels.recipe import library_digest
    table = "" if machine is None else f"|{machine}"
    key = "m" + hashlib.sha256(f"cycles|{kern.code.key}|{library_digest()}{table}".encode()).hexdigest()[:40]
    if key not in _cycles:
        stored = cache.disk_get(key, ".m") if kern.build.cache else None
        try:
            _cycles[key] = float(stored.decode()) if stored is not None else float("nan")
        except ValueError:
            _cycles[key] = float("nan")
        if _cycles[key] != _cycles[key]:  # not stored (or unreadable): model it
            _cycles[key] = float(kernel_cycles(kern, machine))
            if kern.build.cache:
                cache.disk_put(key, repr(_cycles[key]).encode(), ".m")
    return _cycles[key]


def _site_tuple(chosen: dict, fma) -> tuple:
    return tuple(sorted(Site(w, r, t, fma) for (w, r), t in chosen.items()))


def _neighbours(rows: dict, names: list[str], steps: int, within: dict) -> dict:
    """Each row with one float input moved by 1..``steps`` float32 steps either way (the others
    kept), but not out of its declared domain's hull (``within``: name -> (lo, hi, nan), from
    ``domains.hulls``): where a reference output is near a boundary, its neighbours straddle it."""
    out: dict[str, list] = {n: [] for n in rows}
    for n in names:
        v = rows[n]
        if v.dtype != np.float32:
            continue
        bits = v.view(np.int32).astype(np.int64)
        for k in range(1, steps + 1):
            for sign in (1, -1):
                moved = _step(v, bits, sign * k)
                if n in within:
                    moved = np.clip(moved, np.float32(within[n][0]), np.float32(within[n][1]))
                for m in rows:
                    out[m].append(moved if m == n else rows[m])
    if not out[names[0]]:
        return {n: rows[n][:0] for n in rows}
    return {n: np.concatenate(vs) for n, vs in out.items()}


def _step(v: np.ndarray, bits: np.ndarray, k: int) -> np.ndarray:
    """``v`` moved ``k`` float32 steps along the ordered line (through zero, never into NaN)."""
    ordered = np.where(bits < 0, -(bits & 0x7FFFFFFF), bits) + k
    ordered = np.clip(ordered, -0x7F7FFFFF, 0x7F7FFFFF)
    back = np.where(ordered < 0, (-ordered) | 0x80000000, ordered).astype(np.uint32)
    return back.view(np.float32).reshape(v.shape)


def _plain(value):
    value = np.asarray(value)
    return value.item() if value.ndim == 0 else value.tolist()


def _short(where: str) -> str:
    import os
    path, _, line = where.rpartition(":")
    return f"{os.path.basename(path)}:{line}"
