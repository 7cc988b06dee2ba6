"""``python -m routines docs [--measurements DIR] [--out DIR]``

Writes docs/routines/<function>.md for every routine: the algorithm (the
implementing module's docstring), its polynomials with provenance, its
special values, and the accuracy and speed of every variant, taken from the
JSON files that the measuring commands wrote into DIR (default ``out/``):

    python -m routines accuracy F --precision P --fma on|off --exhaustive --json out/accuracy/F_P_fma.json
    python -m routines bench --json out/bench.json

A variant without an exhaustive measurement is measured on the quick sample
now, and its row says so; a function missing from ``out/bench.json`` (or
without that file) is timed now by ``bench``'s own method (64K elements,
interleaved rounds, best round) against NumPy and the libmvec and SLEEF peers
that are installed.
``--functions`` writes only the pages of the functions named.
"""
from __future__ import annotations

import inspect
import json
import os
import re


from .. import NAMES, exponential, logarithm, polynomials, power, reciprocal, specials, trig
from ..base import PRECISIONS
from ..lab.tolerance import tolerance
from . import parser as command_parser
from .accuracy import measure

TRIG = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
MODULES = {"exp2": exponential, "exp": exponential, "log2": logarithm, "log": logarithm,
           "pow": power, "rcp": reciprocal, "rsqrt": reciprocal, "sqrt": reciprocal,
           **{name: trig for name in TRIG}}
_SINCOS = ("sin.full", "sin.relaxed", "cos.full", "cos.relaxed")
POLYS = {"exp2": ("exp2.full", "exp2.relaxed"), "exp": ("exp2.full", "exp2.relaxed"),
         "log2": ("log2.full", "log2.relaxed"), "log": ("log2.full", "log2.relaxed"),
         "pow": ("exp2.full", "exp2.relaxed", "log2.full", "log2.relaxed"),
         "sin": _SINCOS, "cos": _SINCOS, "tan": _SINCOS,
         "asin": ("asin.full", "asin.relaxed"), "acos": ("asin.full", "asin.relaxed"),
         "atan": ("atan.full", "atan.relaxed"), "atan2": ("atan.full", "atan.relaxed"),
         "sinh": ("sinh.full", "sinh.relaxed", "exp.full", "exp.relaxed"),
         "cosh": ("exp.full", "exp.relaxed"),
         "tanh": ("tanh.full", "tanh.relaxed", "exp.full", "exp.relaxed")}
def _algorithm(name: str) -> str:
    """The implementing module's docstring; for routines/trig.py its introduction and the
    section of the function (sections are titled by the functions they cover)."""
    doc = inspect.getdoc(MODULES[name]) or ""
    if name not in TRIG:
        return doc
    parts = re.split(r"\n(?=[^\n]+\n-{3,}\n)", doc)
    intro, sections = parts[0], parts[1:]
    mine = [sec for sec in sections if name in re.split(r"[ ,:]+", sec.split("\n", 1)[0])]
    return "\n\n".join([intro.strip()] + [sec.strip() for sec in mine])


def time_now(name: str, size: int = 65536, rounds: int = 7) -> list[dict]:
    """``bench``'s rows for one function, measured now: every variant, NumPy's float32
    function and the installed libmvec/SLEEF peers on the same arguments."""
    from .bench import run
    return run([name], size, rounds)


def accuracy_path(root: str, name: str, precision: str, fma: bool) -> str:
    return os.path.join(root, "accuracy", f"{name}_{precision}_{'fma' if fma else 'nofma'}.json")


def _accuracy_rows(name: str, root: str):
    rows, regions = [], []
    for precision in PRECISIONS:
        for fma in (True, False):
            path = accuracy_path(root, name, precision, fma)
            if os.path.exists(path):
                with open(path) as f:
                    data = json.load(f)
                how = "exhaustive" if data.get("exhaustive") else "sampled"
            else:
                data = measure(name, precision, fma, progress=False).to_json()
                how = "sampled (quick)"
            mism = sum(data["special_mismatches"].values())
            cmd = (f"python -m routines accuracy {name} --precision {precision} --fma {'on' if fma else 'off'}"
                   + (" --exhaustive" if how == "exhaustive" else ""))
            rows.append(f"| {precision} | {'on' if fma else 'off'} | {_num(data['max_ulp32'], 3)} | "
                        f"{_num(data['max_ulp16'], 4)} | {_num(data['max_margin'], 3, 'g')} | {data['nonconforming']} | "
                        f"{mism} | {data['flushed_to_zero']} | {how}: `{cmd}` |")
            for region, r in data.get("regions", {}).items():
                regions.append(f"| {precision} | {'on' if fma else 'off'} | {region} | {int(r['count'])} | "
                               f"{_num(r['max_abs'], 3, 'g')} | {_num(r['max_ulp32'], 3)} | "
                               f"{_num(r['max_ulp16'], 4)} | {_num(r['max_margin'], 3, 'g')} | {_at(r['max_ulp32_at'], name)} | "
                               f"{how} |")
    if regions:
        rows += ["", "By region of the argument (scored inputs only; the margin is 0 where Vulkan sets no bound):",
                 "", "| precision | FMA | region | inputs | max abs error | max ULP-32 | max ULP-16 | max margin | "
                     "max ULP-32 at | how measured |", "|---|---|---|---|---|---|---|---|---|---|"] + regions
    return rows


def _num(v, digits: int, kind: str = "f") -> str:
    return str(v) if isinstance(v, str) else f"{v:.{digits}{kind}}"


def _at(case, name: str) -> str:
    """The input of a case, as the function's call (the lab's x, y are its operands in order)."""
    if not case:
        return "-"
    args = [case[k] for k in ("x", "y") if k in case]
    return f"{name}({', '.join(f'{a:.9g}' if isinstance(a, float) else str(a) for a in args)})"


def _speed_rows(name: str, root: str):
    path = os.path.join(root, "bench.json")
    header = ["| variant | ns/element | vs NumPy |", "|---|---|---|"]
    data: dict = {}
    if os.path.exists(path):
        with open(path) as f:
            data = json.load(f)
    how = "by `python -m routines bench --json out/bench.json`"
    if not any(r["function"] == name for r in data.get("rows", [])):
        data = {"size": 65536, "rows": time_now(name)}
        import reactor
        host = reactor.get_target("host")
        how = ("by `python -m routines docs` (`routines.cli.docs.time_now`: `python -m routines bench`'s "
               f"method and peers) on the machine that wrote this page (LLVM CPU {host.cpu}, "
               f"{host.natural_width} float32 lanes)")
    rows = list(header)
    for r in data["rows"]:
        if r["function"] != name:
            continue
        if r.get("absent"):
            rows.append(f"| {r['variant']} | absent: {r['absent']} | |")
        else:
            rows.append(f"| {r['variant']} | {r['ns_per_element']:.4f} | {r['speedup_vs_numpy']:.2f}x |")
    return rows + [f"\nMeasured at {data['size']} float32 elements per call {how} "
                   f"(best of interleaved rounds)."]


def _tolerance_rows(name: str):
    rows = ["| precision | Vulkan tolerance | source |", "|---|---|---|"]
    for precision in PRECISIONS:
        t = tolerance(name, precision)
        rows.append(f"| {precision} | {t.rule} ({t.unit}) | {t.citation} |")
    return rows + ["", "Derivations of the inherited bounds: docs/accuracy.md."]


def page(name: str, root: str) -> str:
    out = [f"# {name}\n", "## Algorithm\n", "```", _algorithm(name), "```\n"]
    polys = [p for p in polynomials.ALL if p.name in POLYS.get(name, ())]
    if polys:
        out += ["## Polynomials\n", "| name | approximates | interval | weight | degree | coefficients (high to low) | provenance | measured |",
                "|---|---|---|---|---|---|---|---|"]
        for p in polys:
            out.append(f"| {p.name} | {p.function} | [{p.interval[0]}, {p.interval[1]}] | {p.weight} | "
                       f"{p.degree} | {', '.join(p.coefficients)} | {p.provenance} | {p.measured or 'see Accuracy'} |")
        out.append("")
    out += ["## Special values\n", specials.markdown().split(f"### {name}\n", 1)[1].split("\n### ", 1)[0], ""]
    out += ["## Tolerance\n"] + _tolerance_rows(name) + [""]
    out += ["## Accuracy\n",
            "Vulkan margin = error / tolerance (conforming when < 1); see docs/accuracy.md for the "
            "tolerances and the reference.\n",
            "| precision | FMA | max ULP-32 | max ULP-16 | max margin | non-conforming | special mismatches | "
            "flushed | how measured |", "|---|---|---|---|---|---|---|---|---|"]
    out += _accuracy_rows(name, root) + ["", "## Speed\n"] + _speed_rows(name, root)
    return "\n".join(out) + "\n"


def main(argv: list[str]) -> int:
    parser = command_parser("docs", __doc__, ("", "--measurements out --out docs/routines",
                                              "--functions sin cos"))
    parser.add_argument("--measurements", default="out", metavar="DIR",
                        help="where the measuring commands wrote their JSON (default out/)")
    parser.add_argument("--out", default=os.path.join("docs", "routines"), metavar="DIR",
                        help="where the pages go (default docs/routines/)")
    parser.add_argument("--functions", nargs="+", default=list(NAMES), choices=NAMES, metavar="F",
                        help=f"only these pages (default all: {' '.join(NAMES)})")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for name in args.functions:
        with open(os.path.join(args.out, f"{name}.md"), "w") as f:
            f.write(page(name, args.measurements))
        print(f"wrote {os.path.join(args.out, name + '.md')}")
    return 0
