"""``python -m routines docs [--measurements DIR] [--out DIR]``

Writes docs/routines/<function>.md for every routine: the algorithm (the
implementing module's docstring), its polynomials with provenance, its
special values, and the accuracy and speed of every variant, taken from the
JSON files that the measuring commands wrote into DIR (default ``out/``):

    python -m routines accuracy F --precision P --fma on|off --exhaustive --json out/accuracy/F_P_fma.json
    python -m routines bench --json out/bench.json

A variant without an exhaustive measurement is measured on the quick sample
now, and its row says so.
"""
from __future__ import annotations

import inspect
import json
import os

from .. import NAMES, exponential, logarithm, polynomials, power, reciprocal, specials
from ..base import PRECISIONS
from . import parser as command_parser
from .accuracy import measure

MODULES = {"exp2": exponential, "exp": exponential, "log2": logarithm, "log": logarithm,
           "pow": power, "rcp": reciprocal, "rsqrt": reciprocal, "sqrt": reciprocal}
POLYS = {"exp2": ("exp2.full", "exp2.relaxed"), "exp": ("exp2.full", "exp2.relaxed"),
         "log2": ("log2.full", "log2.relaxed"), "log": ("log2.full", "log2.relaxed"),
         "pow": ("exp2.full", "exp2.relaxed", "log2.full", "log2.relaxed")}


def accuracy_path(root: str, name: str, precision: str, fma: bool) -> str:
    return os.path.join(root, "accuracy", f"{name}_{precision}_{'fma' if fma else 'nofma'}.json")


def _accuracy_rows(name: str, root: str):
    rows = []
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
            rows.append(f"| {precision} | {'on' if fma else 'off'} | {data['max_ulp32']:.3f} | "
                        f"{data['max_ulp16']:.4f} | {data['max_margin']:.3f} | {data['nonconforming']} | "
                        f"{mism} | {data['flushed_to_zero']} | {how}: `{cmd}` |")
    return rows


def _speed_rows(name: str, root: str):
    path = os.path.join(root, "bench.json")
    if not os.path.exists(path):
        return ["(no speed measurement yet: run `python -m routines bench --json out/bench.json`)"]
    with open(path) as f:
        data = json.load(f)
    rows = ["| variant | ns/element | vs NumPy |", "|---|---|---|"]
    for r in data["rows"]:
        if r["function"] == name:
            rows.append(f"| {r['variant']} | {r['ns_per_element']:.4f} | {r['speedup_vs_numpy']:.2f}x |")
    return rows + [f"\nMeasured at {data['size']} float32 elements per call by "
                   f"`python -m routines bench --json out/bench.json` (best of interleaved rounds)."]


def page(name: str, root: str) -> str:
    module = MODULES[name]
    out = [f"# {name}\n", "## Algorithm\n", "```", inspect.getdoc(module), "```\n"]
    polys = [p for p in polynomials.ALL if p.name in POLYS.get(name, ())]
    if polys:
        out += ["## Polynomials\n", "| name | approximates | interval | weight | degree | coefficients (high to low) | provenance | measured |",
                "|---|---|---|---|---|---|---|---|"]
        for p in polys:
            out.append(f"| {p.name} | {p.function} | [{p.interval[0]}, {p.interval[1]}] | {p.weight} | "
                       f"{p.degree} | {', '.join(p.coefficients)} | {p.provenance} | {p.measured or 'see Accuracy'} |")
        out.append("")
    out += ["## Special values\n", specials.markdown().split(f"### {name}\n", 1)[1].split("\n### ", 1)[0], ""]
    out += ["## Accuracy\n",
            "Vulkan margin = error / tolerance (conforming when < 1); see docs/accuracy.md for the "
            "tolerances and the reference.\n",
            "| precision | FMA | max ULP-32 | max ULP-16 | max margin | non-conforming | special mismatches | "
            "flushed | how measured |", "|---|---|---|---|---|---|---|---|---|"]
    out += _accuracy_rows(name, root) + ["", "## Speed\n"] + _speed_rows(name, root)
    return "\n".join(out) + "\n"


def main(argv: list[str]) -> int:
    parser = command_parser("docs", __doc__, ("", "--measurements out --out docs/routines"))
    parser.add_argument("--measurements", default="out", metavar="DIR",
                        help="where the measuring commands wrote their JSON (default out/)")
    parser.add_argument("--out", default=os.path.join("docs", "routines"), metavar="DIR",
                        help="where the pages go (default docs/routines/)")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for name in NAMES:
        with open(os.path.join(args.out, f"{name}.md"), "w") as f:
            f.write(page(name, args.measurements))
        print(f"wrote {os.path.join(args.out, name + '.md')}")
    return 0
