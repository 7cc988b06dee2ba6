"""Reading the IR: exp2 built with FMA on and off, the IR and assembly of both, and what differs.

    python examples/inspect_ir.py [--out out/examples] [--width 4] [--quiet]

``routines.exp2`` is a builder: called inside a ``@reactor.function`` it emits
inline IR. The same body is built twice, with ``fma=True`` and ``fma=False``;
``MulAdd`` in the polynomial becomes ``llvm.fma`` (one rounding, VFMADD) or
``fmul`` + ``fadd`` (two roundings, VMULPS + VADDPS). The example shows both
builds through ``reactor.explain`` (each source line with its IR and assembly,
the routine as its own group), their diff line by line, and an HTML page with
the three linked columns (``inspect_ir.html``); it counts FMA instructions in the ready-made ufuncs
(``routines.jit("exp2", fma=...)``), and measures what the fused rounding
buys in accuracy. Last, it shows how to dump any routine of your own, from
Python and from the command line. The figure puts the two assemblies side by
side with the differing lines marked, beside the error of both builds.
"""
from __future__ import annotations

import argparse
import contextlib
import difflib
import io
import os
import sys
import re

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the examples' common.py, however run
from common import save_png  # noqa: E402

import reactor
import routines
from reactor import SIMD


# A routine of your own, to dump: a Blinn-Phong highlight with relaxed pow. Functions compile
# when first called or asked for their code, so defining them here costs nothing.
@reactor.function
def highlight(n_dot_h: SIMD.Float, shininess: SIMD.Float) -> SIMD.Float:
    return routines.pow(n_dot_h, shininess, precision="relaxed") * 0.8


def build_exp2(width: int | None):
    """exp2 in full precision as a Function of one SIMD vector (explain builds it twice)."""
    def exp2(x: SIMD.Float) -> SIMD.Float:
        return routines.exp2(x, precision="full")
    return reactor.function(exp2, width=width)


def function_body(asm: str, name: str) -> list[str]:
    """The instructions of function ``name`` in an assembly listing (labels and directives dropped)."""
    lines = asm.splitlines()
    start = lines.index(f"{name}:") + 1
    body = []
    for line in lines[start:]:
        if line.startswith(".Lfunc_end"):
            break
        if line.startswith("\t") and not line.lstrip().startswith("."):
            body.append(line.strip().replace("\t", " "))
    return body


def count(pattern: str, text: str) -> int:
    return len(re.findall(pattern, text, flags=re.MULTILINE))


def ulp_errors(kernel, x: np.ndarray) -> np.ndarray:
    """|kernel(x) - 2^x| in float32 ULPs of the exact result (float64 reference)."""
    ref = np.exp2(x.astype(np.float64))
    ulp = np.exp2(np.floor(np.log2(ref)) - 23)
    return np.abs(kernel(x).astype(np.float64) - ref) / ulp


def run(width: int | None = 4, quiet: bool = False, out: str | None = None) -> dict:
    say = (lambda *a, **k: None) if quiet else print
    function = build_exp2(width)
    w = width or "natural"
    # reactor.explain: the code of each source line (and of each routine called there), per build
    on, off = reactor.explain(function, fma=True), reactor.explain(function, fma=False)
    changes = on.diff(off)

    say(f"=== exp2 (full precision, width {w}), FMA on: each line's IR and assembly ===")
    say(on.text())
    say("=== FMA off ===")
    say(off.text())
    say("=== the two builds line by line (≠: the machine code differs) ===")
    say(changes.text())
    if out:
        page = on.write_html(os.path.join(out, "inspect_ir.html"), changes)
        say(f"wrote {page} (three linked columns: hover a line to see its instructions)")

    body_on = [i.text for row in on.lines for i in row.asm]
    body_off = [i.text for row in off.lines for i in row.asm]
    ir_on, ir_off = "\n".join(i.text for r in on.lines for i in r.ir), "\n".join(i.text for r in off.lines for i in r.ir)
    fma_re = r"^\s*vfn?m(add|sub)\w*"
    fma_call = r"call .*@\"?llvm\.fma\."
    results = {
        "ir_fma_calls": {"on": count(fma_call, ir_on), "off": count(fma_call, ir_off)},
        "ir_lines_differing": len(changes.changed()),
        "asm_instructions": {"on": len(body_on), "off": len(body_off)},
        "asm_fma": {"on": count(fma_re, "\n".join(body_on)), "off": count(fma_re, "\n".join(body_off))},
        "asm_mul_add": {k: (count(r"^vmulps", "\n".join(b)), count(r"^vaddps", "\n".join(b)))
                        for k, b in (("on", body_on), ("off", body_off))},
        "body": {"on": body_on, "off": body_off},
        "changed_lines": [(x or y).label for x, y in changes.changed()],
    }

    # the ready-made ufuncs: the same two variants as the library ships them
    kernels = {fma: routines.jit("exp2", precision="full", fma=fma) for fma in (True, False)}
    asm = {fma: reactor.kernel_of(k).assembly for fma, k in kernels.items()}
    results["ufunc_vfmadd"] = {"on": count(r"^\s*vfmadd", asm[True]), "off": count(r"^\s*vfmadd", asm[False])}

    # what the fused rounding buys: the error of both over [-8, 8)
    x = np.linspace(-8, 8, 1 << 20, endpoint=False, dtype=np.float32)
    errs = {fma: ulp_errors(k, x) for fma, k in kernels.items()}
    results["max_ulp"] = {"on": float(errs[True].max()), "off": float(errs[False].max())}
    results["mean_ulp"] = {"on": float(errs[True].mean()), "off": float(errs[False].mean())}
    results["curve"] = (x, errs)

    print("=== summary ===")
    print(f"IR: {results['ir_fma_calls']['on']} llvm.fma calls with FMA on, {results['ir_fma_calls']['off']} "
        f"with FMA off; the code of {results['ir_lines_differing']} line(s) differs: "
        f"{', '.join(results['changed_lines'])}.")
    print(f"assembly of exp2: {len(body_on)} instructions with FMA "
        f"({results['asm_fma']['on']} vfmadd), {len(body_off)} without "
        f"({results['asm_fma']['off']} vfmadd, {results['asm_mul_add']['off'][0]} vmulps + "
        f"{results['asm_mul_add']['off'][1]} vaddps).")
    print(f"ufuncs routines.jit('exp2', fma=...): vfmadd in the FMA build {results['ufunc_vfmadd']['on']}, "
        f"in the other {results['ufunc_vfmadd']['off']}.")
    print(f"error on 2^20 points in [-8, 8): FMA on max {results['max_ulp']['on']:.3f} ULP "
        f"(mean {results['mean_ulp']['on']:.3f}), FMA off max {results['max_ulp']['off']:.3f} ULP "
        f"(mean {results['mean_ulp']['off']:.3f}).")

    # dumping a routine of your own
    print("=== dumping your own routine ===")
    print("From Python:  highlight.compile().assembly   (a @reactor.function)")
    print("              reactor.kernel_of(my_ufunc).ir  (a @reactor.kernel; also .optimized_ir, .assembly)")
    print(f"From a shell: python -m reactor dump {os.path.relpath(__file__)}:highlight --what asm --fma off")
    from reactor.__main__ import main as reactor_cli
    captured = io.StringIO()
    with contextlib.redirect_stdout(captured):
        status = reactor_cli(["dump", f"{__file__}:highlight", "--what", "asm", "--fma", "off"])
    dump = captured.getvalue()
    own = function_body(dump, "highlight")
    results["dump"] = {"status": status, "instructions": len(own), "vfmadd": count(r"^vfmadd", "\n".join(own))}
    print(f"  -> exit status {status}; 'highlight' is {len(own)} instructions, "
        f"{results['dump']['vfmadd']} vfmadd (FMA off). Its first lines:")
    print("\n".join("    " + line for line in own[:8]))
    return results


def save_figure(r: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    on, off = r["body"]["on"], r["body"]["off"]
    fig = plt.figure(figsize=(10.0, 3.8), dpi=90)
    grid = fig.add_gridspec(1, 3, width_ratios=[0.9, 0.9, 1.1])
    # mark the lines that are not common to both listings
    matcher = difflib.SequenceMatcher(a=on, b=off, autojunk=False)
    only_on, only_off = set(range(len(on))), set(range(len(off)))
    for block in matcher.get_matching_blocks():
        only_on -= set(range(block.a, block.a + block.size))
        only_off -= set(range(block.b, block.b + block.size))
    for col, (lines, marked, title) in enumerate(((on, only_on, f"FMA on: {len(on)} instructions"),
                                                  (off, only_off, f"FMA off: {len(off)} instructions"))):
        ax = fig.add_subplot(grid[col])
        ax.set_xlim(0, 1)
        ax.set_ylim(len(off) + 0.5, -0.5)
        ax.axis("off")
        ax.set_title(title, fontsize=9)
        for i, line in enumerate(lines):
            short = re.sub(r"\.LCPI\d+_(\d+)\(%rip\)", r"c\1", line)
            if i in marked:
                ax.add_patch(plt.Rectangle((0, i - 0.5), 1, 1, color="#ffd9a0" if col == 0 else "#b9e0ff", lw=0))
            ax.text(0.01, i, short, family="monospace", fontsize=6.6, va="center")
    ax = fig.add_subplot(grid[2])
    x, errs = r["curve"]
    bins = 128
    for fma, colour in ((False, "#1f77b4"), (True, "#ff7f0e")):
        key = "on" if fma else "off"
        e = errs[fma].reshape(bins, -1)
        centres = x.reshape(bins, -1).mean(axis=1)
        ax.step(centres, e.max(axis=1), where="mid", lw=0.9, color=colour,
                label=f"FMA {key}: max {r['max_ulp'][key]:.2f} ULP")
        ax.step(centres, e.mean(axis=1), where="mid", lw=0.9, color=colour, ls="--",
                label=f"FMA {key}: mean {r['mean_ulp'][key]:.3f} ULP")
    ax.set_xlabel("x", fontsize=8)
    ax.set_ylabel("exp2 error, float32 ULP (per bin)", fontsize=8)
    ax.set_title("fewer instructions, about the same error", fontsize=9)
    ax.tick_params(labelsize=7)
    ax.set_ylim(0, 4.6)
    ax.legend(fontsize=6.5, loc="upper center", ncol=2)
    fig.tight_layout()
    save_png(fig, path)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    parser.add_argument("--width", type=int, choices=(0, 1, 4, 8, 16), default=4,
                        help="SIMD width of the printed builds (4 keeps the IR readable; 0: the target's)")
    parser.add_argument("--quiet", action="store_true", help="print the summary only, not the listings")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    r = run(width=args.width or None, quiet=args.quiet, out=args.out)
    path = os.path.join(args.out, "inspect_ir.png")
    save_figure(r, path)
    print(f"wrote {path}")
    del r["curve"]
    r["image"] = path
    return r


if __name__ == "__main__":
    main()
