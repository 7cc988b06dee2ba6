"""Run fuzz programs: compile at widths 1, 4, 8 and 16, run on many inputs
(special values included), compare every lane with the NumPy evaluation.

``check(program, seed)`` runs one program and returns a ``Result``;
``fuzz(budget, seed)`` runs many. The ``fuzz`` command
(``python -m fuzz --budget N --seed S``) runs them in a worker
process, so a hard crash (a signal) is counted and reported with its program
and the run goes on with the next one.
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import subprocess
import sys
import time
import traceback
import zlib

import numpy as np

import reactor

from . import ast as A
from .emit import function_of, kernel_of_program
from .evaluate import EvaluatorError, evaluate
from .ops import is_snan
from .generate import DOUBLE_CONSTS, FLOAT_CONSTS, INT_CONSTS, RUNNABLE_FORCED, UINT_CONSTS, RandomChooser, generate

WIDTHS = reactor.WIDTHS
_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the directory holding this package
LANES = 256  # input lanes per program (a multiple of 16)


# -- inputs ------------------------------------------------------------------------

# special float32 values, and bit patterns a Python float cannot carry (a signalling NaN, a negative NaN)
FLOAT_SPECIALS = np.concatenate([np.array(FLOAT_CONSTS, np.float32), np.array(
    [0xFFC00000, 0x7FA00000, 0x7FC00001, 0x807FFFFF, 0x00000001, 0x3F7FFFFF, 0x4B000001, 0xCF000000, 0x4F7FFFFF],
    np.uint32).view(np.float32)])
DOUBLE_SPECIALS = np.array(DOUBLE_CONSTS, np.float64)
INT_SPECIALS = np.array([v & 0xFFFFFFFF for v in INT_CONSTS], np.uint32).view(np.int32)
UINT_SPECIALS = np.array(UINT_CONSTS, np.uint32)


def make_data(kind: str, rng: np.random.Generator, lanes: int = LANES) -> np.ndarray:
    """``lanes`` values of ``kind`` in blocks of 16 lanes, each block in one style:
    special values, ordinary random values, small integers, or one repeated value
    (so that Any/All and uniform branches go both ways)."""
    out = np.empty(lanes, A.DTYPES[kind])
    for b in range(0, lanes, 16):
        style = rng.integers(0, 4)
        if kind == "Bool":
            p = [0.0, 0.1, 0.5, 0.9, 1.0][rng.integers(0, 5)]
            out[b:b + 16] = rng.random(16) < p
            continue
        if kind in ("Float", "Double"):
            specials = FLOAT_SPECIALS if kind == "Float" else DOUBLE_SPECIALS
            if style == 0:
                block = rng.choice(specials, 16)
            elif style == 1:
                block = rng.standard_normal(16) * 10.0 ** rng.integers(-3, 4, 16)
                if rng.random() < 0.3:  # raw bit patterns: every class, NaN payloads, subnormals
                    bits = rng.integers(0, 2**32 if kind == "Float" else 2**63, 16, dtype=np.uint64)
                    block = bits.astype(np.uint32).view(np.float32) if kind == "Float" else bits.view(np.float64)
            elif style == 2:
                block = rng.integers(-8, 9, 16).astype(np.float64) / rng.choice([1, 2, 4])
            else:
                block = np.full(16, rng.choice(specials) if rng.random() < 0.5 else rng.integers(-3, 4))
        else:
            specials = INT_SPECIALS if kind == "Int" else UINT_SPECIALS
            if style == 0:
                block = rng.choice(specials, 16)
            elif style == 1:
                block = rng.integers(0, 2**32, 16, dtype=np.uint64).astype(np.uint32)
            elif style == 2:
                block = rng.integers(-20, 21, 16)
            else:
                block = np.full(16, rng.choice(specials) if rng.random() < 0.5 else rng.integers(0, 8))
            block = np.asarray(block).astype(np.int64).astype(np.uint32)
        with np.errstate(all="ignore"):
            out[b:b + 16] = np.asarray(block).astype(out.dtype) if kind not in ("Int", "UInt") \
                else np.asarray(block, np.uint32).view(np.int32 if kind == "Int" else np.uint32)
    return out


def make_inputs(program: A.Program, seed, lanes: int = LANES):
    rng = np.random.default_rng(seed)
    return [make_data(t.kind, rng, lanes) for t in program.inputs]


# -- comparing ----------------------------------------------------------------------

def differ(got: np.ndarray, want: np.ndarray, taint: np.ndarray) -> np.ndarray:
    """Indices of lanes that differ: bit-exact, any NaN matches any NaN, tainted lanes skipped."""
    got, want = np.asarray(got), np.asarray(want)
    if got.dtype != want.dtype:
        raise EvaluatorError(f"dtype {got.dtype} vs {want.dtype}")
    if got.dtype.kind == "f":
        ints = np.uint32 if got.dtype.itemsize == 4 else np.uint64
        same = (np.ascontiguousarray(got).view(ints) == np.ascontiguousarray(want).view(ints)) | \
            (np.isnan(got) & np.isnan(want))
    else:
        same = got == want
    return np.flatnonzero(~same & ~taint)


@dataclasses.dataclass
class Mismatch:
    width: int
    layout: str
    output: int
    lane: int
    got: object
    want: object
    inputs: list

    def describe(self) -> str:
        return (f"width {self.width} ({self.layout}) output {self.output} lane {self.lane}: "
                f"got {self.got!r}, want {self.want!r}; inputs {self.inputs}")


@dataclasses.dataclass
class Result:
    program: A.Program
    status: str = "ok"  # "ok", "mismatch", "error" (an exception: reactor or fuzzer)
    mismatches: list = dataclasses.field(default_factory=list)
    error: str = ""
    variants: int = 0  # compiled (program, width) pairs
    lanes: int = 0  # lanes compared

    def summary(self) -> str:
        if self.status == "ok":
            return "ok"
        if self.status == "error":
            return f"error: {self.error.strip().splitlines()[-1] if self.error.strip() else '?'}"
        return f"{len(self.mismatches)} mismatching lane(s), first: {self.mismatches[0].describe()}"


def _value(x):
    x = np.asarray(x)[()]
    if isinstance(x, np.floating):
        return f"{float(x)!r} (0x{int(np.asarray(x).view(np.uint32 if x.itemsize == 4 else np.uint64)):x})"
    return x.item()


def _record(res, got, want, taint, inputs, W, layout, j, rows_of=None):
    bad = differ(got, want, taint)
    res.lanes += int(np.size(got) - np.count_nonzero(taint))
    for lane in bad[:4]:
        if rows_of is None:  # the inputs of the lane's whole vector (cross-lane operations see them all)
            row = range(lane - lane % W, lane - lane % W + W)
            ins = [[_value(x[k]) for k in row] for x in inputs]
        else:
            ins = [_value(x) for x in rows_of(lane)]
        res.mismatches.append(Mismatch(W, layout, j, int(lane), _value(got[lane]), _value(want[lane]), ins))
    return len(bad)


# -- running -----------------------------------------------------------------------

def _run_function(program, inputs, widths, res, name):
    fn = function_of(program, name)
    lanes = inputs[0].size
    for W in widths:
        routine = fn.compile(width=W)
        res.variants += 1
        outs = [np.zeros(lanes, o.ty.dtype) for o in program.outputs]
        routine(*inputs, *outs, lanes // W)
        want, taint = evaluate(program, inputs, W)
        for j, (g, w, t) in enumerate(zip(outs, want, taint)):
            _record(res, g, w, t, inputs, W, "function", j)


def _as_tuple(x):
    return x if isinstance(x, tuple) else (x,)


def _run_kernel(program, inputs, widths, res, name, rng):
    nin = len(inputs)
    want, taint = evaluate(program, inputs, 1)
    lanes = inputs[0].size
    for W in widths:
        uf = kernel_of_program(program, W, name=f"{name}_w{W}")
        res.variants += 1
        cases = [("contiguous", [x for x in inputs], slice(None))]
        for n in sorted({0, 1, W - 1, W + 1, 2 * W + 3, 37} - {-1}):
            cases.append((f"first {n}", [x[:n] for x in inputs], slice(0, n)))
        cases.append(("stride 3", [x[::3] for x in inputs], slice(None, None, 3)))
        cases.append(("reversed", [x[::-1] for x in inputs], slice(None, None, -1)))
        for layout, args, sel in cases:
            got = _as_tuple(uf(*args))
            for j, g in enumerate(got):
                _record(res, g, want[j][sel], taint[j][sel], [x[sel] for x in inputs], 1, f"{layout}", j,
                        rows_of=lambda lane, sel=sel: [x[sel][lane] for x in inputs])
        # strided outputs
        outs = tuple(np.zeros(2 * lanes, o.ty.dtype)[::2] for o in program.outputs)
        uf(*inputs, out=outs if len(outs) > 1 else outs[0])
        for j, g in enumerate(outs):
            _record(res, g, want[j], taint[j], inputs, 1, "strided out", j,
                    rows_of=lambda lane: [x[lane] for x in inputs])
        # one input broadcast from a 0-d array (the vector loop's broadcast layouts)
        for k in range(nin):
            pick = int(rng.integers(0, lanes))
            args = list(inputs)
            args[k] = np.asarray(inputs[k][pick])
            full = [np.broadcast_to(a, (lanes,)).copy() for a in args]
            w2, t2 = evaluate(program, full, 1)
            got = _as_tuple(uf(*args))
            m = lanes if nin > 1 else 1  # one 0-d input: a 0-d result
            for j, g in enumerate(got):
                _record(res, np.reshape(g, -1), w2[j][:m], t2[j][:m], full, 1, f"input {k} broadcast", j,
                        rows_of=lambda lane, full=full: [x[lane] for x in full])


# -- the same bits on every target ---------------------------------------------------------

#: The default NaN of an invalid arithmetic operation (0 * inf, inf - inf, 0 / 0) per architecture,
#: by item size: x86's has the sign set, AArch64's not. The DSL's operators give the hardware's
#: (docs/dsl.md); the routines and built-ins give x86's on every target.
X86_DEFAULT_NAN = {2: 0xFE00, 4: 0xFFC00000, 8: 0xFFF8000000000000}
ARM_DEFAULT_NAN = {2: 0x7E00, 4: 0x7FC00000, 8: 0x7FF8000000000000}


def cross_targets(program: A.Program) -> list[str]:
    """The other targets a kernel program is also run on: the x86 levels this CPU runs, and
    aarch64 under qemu-user where the cross tools are installed."""
    others = [t for t in ("host",) + tuple(RUNNABLE_FORCED) if t != program.target]
    return others + (["aarch64"] if reactor.emulator_missing() is None else [])


def same_bits(got: np.ndarray, want: np.ndarray, taint: np.ndarray, arch: str) -> np.ndarray:
    """Indices of lanes whose bits differ, NaN payloads and signs included, except an invalid
    operation's default NaN on AArch64 (where x86 gives its own) and tainted lanes."""
    got, want = np.ascontiguousarray(got), np.ascontiguousarray(want)
    if got.dtype.kind == "f":
        size = got.dtype.itemsize
        ints = {2: np.uint16, 4: np.uint32, 8: np.uint64}[size]
        g, w = got.view(ints), want.view(ints)
        same = g == w
        if arch == "aarch64":
            same |= (w == X86_DEFAULT_NAN[size]) & (g == ARM_DEFAULT_NAN[size])
    else:
        same = got == want
    return np.flatnonzero(~same & ~taint)


def _run_cross_targets(program, inputs, res, name):
    """The program's kernel on every other target must give its bits on its own target (width 4,
    which every target has), every output, NaN signs and payloads included, except in lanes where
    an operation met two NaNs (the hardware chooses which it returns) and the documented
    exceptions of ``same_bits``."""
    _, taint = evaluate(program, inputs, 1, nan_choice=True)
    ref = _as_tuple(kernel_of_program(program, 4, name=f"{name}_ref")(*inputs))
    for target in cross_targets(program):
        other = dataclasses.replace(program, target=target)
        uf = kernel_of_program(other, 4, name=f"{name}_{target}")
        res.variants += 1
        if reactor.get_target(target).runnable:
            got = _as_tuple(uf(*inputs))
        else:
            got = reactor.run_emulated(uf, *inputs)
            got = got if isinstance(got, tuple) else (got,)
        arch = reactor.get_target(target).arch
        # LLVM may treat a signalling NaN as a quiet one: on AArch64 it turns Min/Max against a
        # non-NaN into FMINNM/FMAXNM, which return the quieted signalling NaN (docs/dsl.md)
        signalling = np.zeros(len(inputs[0]), bool)
        if arch != "x86_64":
            for x in inputs:
                if x.dtype.kind == "f":
                    signalling |= is_snan(x)
        for j, (g, w) in enumerate(zip(got, ref)):
            bad = same_bits(g, w, taint[j] | signalling, arch)
            res.lanes += int(np.size(g))
            for lane in bad[:4]:
                res.mismatches.append(Mismatch(4, f"target {target} vs {program.target}", j, int(lane),
                                               _value(g[lane]), _value(w[lane]),
                                               [_value(x[lane]) for x in inputs]))


def check(program: A.Program, seed=0, widths=WIDTHS, name: str = "fuzz", targets: bool = True) -> Result:
    """Compile and run ``program`` at ``widths`` and compare with NumPy, then (a kernel, with
    ``targets``) its bits on every other target with its own target's; never raises."""
    res = Result(program)
    try:
        inputs = make_inputs(program, seed)
        with np.errstate(all="ignore"):
            if program.mode == "function":
                _run_function(program, inputs, widths, res, name)
            else:
                _run_kernel(program, inputs, widths, res, name, np.random.default_rng(seed))
                if targets:
                    _run_cross_targets(program, inputs, res, name)
    except Exception:  # noqa: BLE001 - a reactor or fuzzer exception is a finding, reported
        res.status, res.error = "error", traceback.format_exc()
        return res
    if res.mismatches:
        res.status = "mismatch"
    return res


def program_for(seed, index: int) -> A.Program:
    """The program number ``index`` of run ``seed`` (independent of the other programs)."""
    return generate(RandomChooser(f"{seed}:{index}"))


# -- many programs -------------------------------------------------------------------

@dataclasses.dataclass
class Stats:
    programs: int = 0
    variants: int = 0
    lanes: int = 0
    mismatches: int = 0
    errors: int = 0
    crashes: int = 0
    seconds: float = 0.0
    ops: dict = dataclasses.field(default_factory=dict)
    findings: list = dataclasses.field(default_factory=list)  # (index, status, summary, repr)

    def add(self, index, res: Result):
        self.programs += 1
        self.variants += res.variants
        self.lanes += res.lanes
        for name in A.op_names(res.program):
            self.ops[name] = self.ops.get(name, 0) + 1
        if res.status == "mismatch":
            self.mismatches += 1
        elif res.status == "error":
            self.errors += 1
        if res.status != "ok":
            self.findings.append((index, res.status, res.summary(), repr(res.program)))

    def report(self) -> str:
        lines = [f"programs tried: {self.programs}  (compiled variants: {self.variants}, "
                 f"lanes compared: {self.lanes})",
                 f"mismatches: {self.mismatches}  errors: {self.errors}  crashes: {self.crashes}",
                 f"time: {self.seconds:.1f} s"]
        if self.ops:
            lines.append("coverage (programs using): " + ", ".join(
                f"{k} {v}" for k, v in sorted(self.ops.items(), key=lambda kv: -kv[1])))
        for index, status, summary, text in self.findings:
            lines.append(f"\n[{status}] program {index}: {summary}")
            if status != "crash":
                lines.append(A.source(A.parse(text)))
            lines.append(f"repr: {text}")
        return "\n".join(lines)


def fuzz(budget: int, seed=0, *, start: int = 0, on_result=None) -> Stats:
    """Run programs ``start .. start + budget - 1`` of run ``seed`` in this process."""
    stats = Stats()
    t0 = time.perf_counter()
    for index in range(start, start + budget):
        program = program_for(seed, index)
        if on_result is not None:
            on_result("start", index, None)
        res = check(program, seed=[_seed_int(seed), index], name=f"fz{index}")
        stats.add(index, res)
        if on_result is not None:
            on_result("done", index, res)
    stats.seconds = time.perf_counter() - t0
    return stats


def _seed_int(seed) -> int:
    return int(seed) if str(seed).isdigit() else zlib.crc32(str(seed).encode())


def _worker(seed, start: int, count: int) -> int:
    """Child process: run programs, one JSON line per event on stdout."""
    def emit(event, index, res):
        msg = {"event": event, "index": index}
        if res is not None:
            msg.update(status=res.status, summary=res.summary() if res.status != "ok" else "",
                       variants=res.variants, lanes=res.lanes, ops=sorted(A.op_names(res.program)),
                       program=repr(res.program) if res.status != "ok" else "")
        sys.stdout.write(json.dumps(msg) + "\n")
        sys.stdout.flush()

    crash_at = os.environ.get("REACTOR_FUZZ_CRASH_AT")  # fault injection, to test crash reporting

    def emit_or_crash(event, index, res):
        emit(event, index, res)
        if event == "start" and crash_at is not None and int(crash_at) == index:
            import signal
            os.kill(os.getpid(), signal.SIGSEGV)

    fuzz(count, seed, start=start, on_result=emit_or_crash)
    return 0


def run_isolated(budget: int, seed=0, progress=None) -> Stats:
    """Run ``budget`` programs in worker processes; a worker killed by a signal is a
    crash of the program it was running, and a new worker continues after it."""
    stats = Stats()
    t0 = time.perf_counter()
    index, end = 0, budget
    while index < end:
        cmd = [sys.executable, "-m", "fuzz", "worker", "--seed", str(seed), "--start", str(index),
               "--count", str(end - index)]
        env = dict(os.environ, REACTOR_CACHE="0", PYTHONPATH=os.pathsep.join(
            [_ROOT] + [p for p in [os.environ.get("PYTHONPATH")] if p]))  # the worker imports this package
        # its own session: Ctrl-C at a terminal reaches this process only, never a worker still
        # starting up (it would print a traceback); this process ends the worker on its way out
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, env=env, text=True, start_new_session=True)
        with _ended_on_exit(proc):
            index, running = _read_worker(proc, stats, index, progress, t0)
        code = proc.wait()
        if code != 0:
            crashed = running if running is not None else index
            stats.programs += 1
            stats.crashes += 1
            text = repr(program_for(seed, crashed))
            stats.findings.append((crashed, "crash", f"worker exited with {code}", text))
            index = crashed + 1
    stats.seconds = time.perf_counter() - t0
    return stats


@contextlib.contextmanager
def _ended_on_exit(proc: subprocess.Popen):
    """Kill ``proc`` if the block is left by an exception (Ctrl-C, a closed pipe)."""
    try:
        yield proc
    except BaseException:
        proc.kill()
        proc.wait()
        raise


def _read_worker(proc: subprocess.Popen, stats: Stats, index: int, progress, t0: float) -> tuple:
    """Add a worker's reported results to ``stats``; return (next index, the program it was
    running when its output ended, or None)."""
    running = None
    for line in proc.stdout:
        msg = json.loads(line)
        if msg["event"] == "start":
            running = msg["index"]
            continue
        stats.programs += 1
        stats.variants += msg["variants"]
        stats.lanes += msg["lanes"]
        for name in msg["ops"]:
            stats.ops[name] = stats.ops.get(name, 0) + 1
        if msg["status"] == "mismatch":
            stats.mismatches += 1
        elif msg["status"] == "error":
            stats.errors += 1
        if msg["status"] != "ok":
            stats.findings.append((msg["index"], msg["status"], msg["summary"], msg["program"]))
        index = msg["index"] + 1
        running = None
        if progress is not None:
            progress(stats, time.perf_counter() - t0)
    return index, running


def add_arguments(parser) -> None:
    """The fuzz command's options (``python -m fuzz``)."""
    from reactor.cli import positive_int

    parser.add_argument("--budget", type=positive_int, metavar="N", default=200,
                        help="number of programs (default 200)")
    parser.add_argument("--seed", default="0", help="run seed (default 0); program k of a seed is always the same")
    parser.add_argument("--in-process", action="store_true",
                        help="run in this process (a hard crash then ends the run)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress line (it is shown only on a terminal anyway)")


def run(args) -> int:
    """Run the fuzz command; print programs tried, mismatches, errors, crashes and each finding."""
    show = not args.quiet and sys.stderr.isatty()  # a progress line, not a log: terminals only

    def progress(stats, seconds):
        if show and (stats.programs % 25 == 0 or stats.programs == args.budget):
            print(f"\r{stats.programs}/{args.budget} programs, {stats.mismatches} mismatches, "
                  f"{stats.errors} errors, {stats.crashes} crashes, {seconds:.0f} s", end="",
                  file=sys.stderr, flush=True)

    if args.in_process:
        stats = Stats()
        t0 = time.perf_counter()

        def on_result(event, index, res):
            if event == "done":
                stats.add(index, res)
                progress(stats, time.perf_counter() - t0)

        fuzz(args.budget, args.seed, on_result=on_result)
        stats.seconds = time.perf_counter() - t0
    else:
        stats = run_isolated(args.budget, args.seed, progress)
    if show:
        print(file=sys.stderr)
    print(stats.report())
    return 0 if stats.mismatches == stats.errors == stats.crashes == 0 else 1


EXAMPLES = ("python -m fuzz --budget 50 --seed 7",
            "python -m fuzz --budget 1000 --seed nightly --quiet > fuzz.log",
            "python -m fuzz --budget 20 --in-process")


def main(argv=None) -> int:
    """``python -m fuzz``; a user's mistake is one line and exit status 2, Ctrl-C one line
    and status 130 (see ``reactor.cli.run``)."""
    from reactor.cli import ArgumentParser
    from reactor.cli import run as run_command

    parser = ArgumentParser(prog="python -m fuzz", examples=EXAMPLES,
                            description="Differential fuzzing of the reactor DSL against NumPy: random "
                                        "programs compiled\nat widths 1, 4, 8 and 16, every lane compared "
                                        "with NumPy. Exit status 1 on a finding.")
    add_arguments(parser)
    return run_command(lambda a: run(parser.parse_args(a)), argv)
