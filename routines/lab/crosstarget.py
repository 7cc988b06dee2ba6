"""The same bits on every target: each routine variant's output on one target against another's.

For each variant (function x precision x FMA) the kernel built for every target
runs on the same inputs (``fingerprint``'s set: specials, subnormals, thresholds,
then a sweep of every binade), contiguous and strided, and every output bit is
compared with the reference target's (the host by default), NaN payloads
included. x86 targets this CPU can run run in process; ``aarch64`` runs under
qemu-user (``reactor.Emulator``), all of its kernels in one executable.
"FMA on" means fused on every target: in hardware where it exists, emulated
exactly where not (``fma="emulate"``); "off" means separately rounded.

``--exhaustive`` compares every one of the 2^32 inputs of the unary variants, in
chunks of 2^24, on the x86 targets this CPU runs (not under emulation: qemu runs
NEON code ~20-50x slower than the hardware).

    python -m routines crosstarget [--targets sse4 avx2 aarch64] [--functions exp2 log2]
                                   [--n 1048576] [--exhaustive] [--json FILE]
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from ..base import LADDER, PRECISIONS, tiers
from .fingerprint import pow_inputs, unary_inputs
from .reference import BINARY

EMULATED = ("aarch64",)
def uses_estimate(name: str, precision: str, fma: bool, target: str) -> bool:
    """Whether the variant's kernel for ``target`` uses a hardware estimate (RCP14/RSQRT14: on
    AVX-512 targets, in rcp, rsqrt, relaxed sqrt and the routines built on them; see
    routines/reciprocal.py), whose bits differ from the exact operations used elsewhere by design."""
    import reactor
    ir = reactor.kernel_of(_ufunc(name, precision, fma, target)).ir
    return "rcp14" in ir or "rsqrt14" in ir


def by_estimate(row: dict) -> bool:
    """Whether a difference in this row is the documented one: an estimate on one side only."""
    sides = [uses_estimate(row["function"], row["precision"], row["fma"], t) for t in (row["target"], row["reference"])]
    return sides[0] != sides[1]


def _fma_option(fma: bool, target: str):
    import reactor
    if not fma:
        return False
    return True if reactor.get_target(target).has_fma else "emulate"


def _ufunc(name: str, precision: str, fma: bool, target: str):
    import routines
    return routines.jit(name, precision=precision, fma=_fma_option(fma, target), target=target)


def _inputs(name: str, n: int) -> tuple[np.ndarray, ...]:
    return pow_inputs(n) if name in BINARY else (unary_inputs(n),)


def _strided(args):
    return tuple(a[: a.size // 64 * 2: 2] for a in args)


def variants(functions, precisions=PRECISIONS):
    """(name, precision, fma) of every variant asked for; a tier a routine lacks is skipped."""
    for name in functions:
        for precision in (p for p in precisions if p in tiers(name)):
            for fma in (True, False):
                yield name, precision, fma


def _differences(ref: np.ndarray, got: np.ndarray, args) -> dict:
    r, g = ref.view(np.uint32), got.view(np.uint32)
    bad = np.flatnonzero(r != g)
    nan_only = bool(bad.size) and bool(np.isnan(ref[bad]).all() and np.isnan(got[bad]).all())
    examples = [{"inputs": [f"{float(a[i])!r} (0x{int(a[i:i + 1].view(np.uint32)[0]):08x})" for a in args],
                 "reference": f"0x{int(r[i]):08x}", "target": f"0x{int(g[i]):08x}"} for i in bad[:3]]
    return {"differ": int(bad.size), "nan_only": nan_only, "examples": examples}


def compare(functions, targets, reference: str = "host", n: int = 2 ** 20, progress=None,
            precisions=PRECISIONS) -> list[dict]:
    """One row per (variant, target): how many of the ``n`` outputs (contiguous, then strided)
    differ from the reference target's in any bit."""
    import reactor

    rows: list[dict] = []
    todo = list(variants(functions, precisions))
    foreign = [t for t in targets if not reactor.get_target(t).runnable]
    runs: dict[tuple, list] = {}
    for target in foreign:
        if target not in EMULATED:
            raise ValueError(f"target {target!r} cannot run on this CPU and has no emulator here")
        ufuncs = [_ufunc(name, p, fma, target) for name, p, fma in todo]
        with reactor.Emulator(ufuncs) as run:
            calls = [(i, _inputs(name, n)) for i, (name, _, _) in enumerate(todo)]
            flat = run(calls)
            strided = run([(i, _strided(args)) for i, args in calls])
        for (key, a, b) in zip(todo, flat, strided):
            runs[key + (target,)] = [a[0], b[0]]
    for name, precision, fma in todo:
        args = _inputs(name, n)
        ref_fn = _ufunc(name, precision, fma, reference)
        ref = [ref_fn(*args), ref_fn(*_strided(args))]
        for target in targets:
            key = (name, precision, fma, target)
            if key not in runs:
                fn = _ufunc(name, precision, fma, target)
                runs[key] = [fn(*args), fn(*_strided(args))]
            got = runs.pop(key)
            flat = _differences(ref[0], got[0], args)
            strided = _differences(ref[1], got[1], _strided(args))
            row = {"function": name, "precision": precision, "fma": fma, "target": target,
                   "reference": reference, "n": int(args[0].size + _strided(args)[0].size),
                   "differ": flat["differ"] + strided["differ"],
                   "nan_only": (flat["nan_only"] or not flat["differ"]) and (strided["nan_only"] or not strided["differ"]),
                   "examples": flat["examples"] or strided["examples"]}
            rows.append(row)
            if progress:
                progress(row)
    return rows


def exhaustive(functions, targets, reference: str = "host", chunk: int = 2 ** 24, progress=None,
               precisions=PRECISIONS) -> list[dict]:
    """Every 2^32 input of each unary variant on each runnable target against the reference."""
    rows = []
    for name, precision, fma in variants(functions, precisions):
        if name in BINARY:
            continue
        ref_fn = _ufunc(name, precision, fma, reference)
        fns = {t: _ufunc(name, precision, fma, t) for t in targets}
        differ = {t: 0 for t in targets}
        examples: dict[str, list] = {t: [] for t in targets}
        start = time.perf_counter()
        for lo in range(0, 2 ** 32, chunk):
            x = np.arange(lo, lo + chunk, dtype=np.uint64).astype(np.uint32).view(np.float32)
            ref = ref_fn(x).view(np.uint32)
            for t, fn in fns.items():
                bad = np.flatnonzero(fn(x).view(np.uint32) != ref)
                differ[t] += int(bad.size)
                if bad.size and len(examples[t]) < 3:
                    examples[t].append(f"0x{lo + int(bad[0]):08x}")
        for t in targets:
            row = {"function": name, "precision": precision, "fma": fma, "target": t, "reference": reference,
                   "n": 2 ** 32, "differ": differ[t], "examples": examples[t],
                   "seconds": round(time.perf_counter() - start, 1)}
            rows.append(row)
            if progress:
                progress(row)
    return rows


def _line(row: dict) -> str:
    fma = "fma" if row["fma"] else "nofma"
    what = "identical" if not row["differ"] else (
        f"{row['differ']} differ" + (" (NaN bits only)" if row.get("nan_only") else "")
        + (" (hardware estimate)" if by_estimate(row) else ""))
    example = f"  e.g. {row['examples'][0]}" if row["differ"] and row["examples"] else ""
    return f"{row['function']:6s} {row['precision']:8s} {fma:6s} {row['target']:8s} vs {row['reference']}: " \
           f"{what} of {row['n']}{example}"


def main(argv=None) -> int:
    import reactor

    from .. import NAMES
    from ..cli import add_quiet, parser as command_parser

    parser = command_parser("crosstarget", __doc__, (
        "--targets sse4 avx2 aarch64", "--functions exp2 log2 --exhaustive --targets sse4 avx2"))
    parser.add_argument("--targets", nargs="+", choices=reactor.TARGETS, metavar="T",
                        help="targets to compare with the reference (default: the x86 levels this CPU "
                             "runs, and aarch64 when qemu-user and the cross toolchain are here)")
    parser.add_argument("--reference", default="host", choices=reactor.TARGETS, help="default: host")
    parser.add_argument("--functions", nargs="+", choices=NAMES, metavar="F", default=list(NAMES),
                        help="default: every routine")
    parser.add_argument("--precisions", nargs="+", choices=LADDER, default=list(PRECISIONS), metavar="P",
                        help="any of " + " ".join(LADDER) + " (a tier a routine lacks is skipped); default: "
                             + " ".join(PRECISIONS))
    parser.add_argument("--n", type=int, default=2 ** 20, help="inputs per variant (default 2^20)")
    parser.add_argument("--exhaustive", action="store_true",
                        help="every 2^32 input of the unary variants (x86 targets this CPU runs)")
    parser.add_argument("--json", metavar="FILE", help="write the rows to this file")
    add_quiet(parser, "only the summary")
    args = parser.parse_args(argv if argv is not None else sys.argv[1:])
    targets = args.targets
    if targets is None:
        targets = [t for t in ("avx512", "avx2", "sse4") if reactor.get_target(t).runnable]
        if not args.exhaustive and reactor.emulator_missing() is None:
            targets.append("aarch64")
    if args.exhaustive and any(not reactor.get_target(t).runnable for t in targets):
        parser.error("--exhaustive runs only targets this CPU can run")
    for t in targets + [args.reference]:
        if not reactor.get_target(t).runnable and (t not in EMULATED or t == args.reference):
            parser.error(f"target {t!r} cannot run on this CPU ({reactor.get_target(t).missing()})"
                         + ("" if t == args.reference else " and has no emulator here"))
        if t in EMULATED and reactor.emulator_missing() is not None:
            parser.error(f"running {t} code needs {reactor.emulator_missing()}")
    progress = None if args.quiet else lambda row: print(_line(row), flush=True)
    start = time.perf_counter()
    if args.exhaustive:
        rows = exhaustive(args.functions, targets, args.reference, progress=progress, precisions=args.precisions)
    else:
        rows = compare(args.functions, targets, args.reference, args.n, progress=progress,
                       precisions=args.precisions)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    expected = [r for r in rows if r["differ"] and by_estimate(r)]
    unexpected = [r for r in rows if r["differ"] and not by_estimate(r)]
    print(f"{len(rows)} comparisons with {args.reference} ({reactor.get_target(args.reference).cpu}) on "
          f"{', '.join(targets)}: {len(rows) - len(expected) - len(unexpected)} identical in every bit, "
          f"{len(expected)} differ by a documented hardware estimate, {len(unexpected)} differ otherwise "
          f"({time.perf_counter() - start:.0f} s)")
    for r in unexpected:
        print("  DIFFERENT: " + _line(r))
    return 1 if unexpected else 0


if __name__ == "__main__":
    sys.exit(main())
