"""``python -m reactor dump TARGET [--what ir|opt|asm] [--fma on|off] [--width N] [--target T]``,
``python -m reactor explain TARGET [--html OUT] [--diff fma=off] [--plumbing] [--input NAME=LO:HI ...]``,
``python -m reactor plan TARGET --input NAME=DOMAIN ... [--output unorm8] [--save PLAN.json]``,
``python -m reactor cache info|clear``

TARGET names what to print:
  FILE.py:NAME           a Function or @kernel ufunc defined in a user's file
  package.module:NAME    the same, from an importable module
(the routine library has its own: ``python -m routines dump NAME``).
"""
from __future__ import annotations

import os
import sys

from .build import options
from .cli import ArgumentParser, add_build_arguments, build_options, load, positive_int, run, text
from .errors import ReactorError

EXAMPLES = ("python -m reactor dump examples/custom_routine.py:falloff --what ir",
            "python -m reactor dump examples/custom_routine.py:falloff --fma off --width 8 --target avx2")


EXPLAIN = """python -m reactor explain TARGET [--html OUT.html] [--diff KEY=VALUE] [--plumbing]
                         [--input NAME=LO:HI|V1,V2,... ...] [--samples N] [build options]

Each Python line of a kernel or Function with the IR and the machine instructions it
became, the routines it called as their own groups, and its cost (operations by pipe,
share of the work, critical path) from the dataflow model, each line weighed by how
often it runs: a loop's body by its trip count, measured when every input of the
kernel is given with --input (N samples, uniform in LO:HI or drawn from the values),
else estimated (a constant bound, or a stated assumption); the header says which.
--diff compares with a second build (fma=off, precision=relaxed, target=avx2, width=8
...) line by line; --html writes only the page (three linked columns) and says where."""
EXPLAIN_EXAMPLES = ("python -m reactor explain examples/custom_routine.py:falloff",
                    "python -m reactor explain examples/custom_routine.py:falloff --diff fma=off --html falloff.html",
                    "python -m reactor explain shade.py:mandel --input cx=-2:0.5 --input cy=-1.25:1.25")


PLAN = """python -m reactor plan TARGET --input NAME=DOMAIN ... [--output FORMAT] [--save PLAN.json]

For every routine call site of a kernel (file:line; built-ins such as normalize count
through the routines they call), the cheapest precision tier that leaves the kernel's
output, stored in FORMAT, identical to the all-most-accurate build's on every input of
the declared domain: exhaustively when the domain can be enumerated, else on a sample
searched around its riskiest inputs (the plan says which).
DOMAIN: unorm8, unorm10, unorm16, float16 (every value of the format), LO:HI (a range,
sampled), or V1,V2,... (values). FORMAT: unorm8, unorm10, unorm16, float16, float32,
ulp:N or abs:E (a tolerance). Tables and textures cannot be declared here: use
reactor.plan() from Python."""
PLAN_EXAMPLES = ("python -m reactor plan examples/plan/scenes.py:srgb_blit --input c=unorm8",
                 "python -m reactor plan examples/plan/scenes.py:exposure --input x=float16 --input stops=-2,-1,0,1,2 "
                 "--output unorm8 --save exposure.plan.json")


GLSL = """python -m reactor glsl FILE --size WxH --out IMAGE.png [--shadertoy] [--time T]

Render a GLSL fragment shader over a pixel grid into a PNG (8-bit RGBA, its first output clamped
to [0, 1]): a shader whose one input is gl_FragCoord, or with --shadertoy a Shadertoy shader
(mainImage(out vec4, in vec2), iResolution set to the size, iTime to T). Needs the glsl extra."""
GLSL_EXAMPLES = ("python -m reactor glsl examples/glsl/rings.frag --shadertoy --size 320x180 --out rings.png",
                 "python -m reactor glsl examples/glsl/rings.frag --shadertoy --size 64x64 --time 2.5 --out rings.png")


CACHE = """python -m reactor cache info|clear

The disk cache of compiled code: $REACTOR_CACHE_DIR, else $XDG_CACHE_HOME/reactor, else
~/.cache/reactor (REACTOR_CACHE=0: none). It is used only when it is this user's and not
writable by others; its entries are authenticated with this user's key, so no one else's
code is ever linked. info shows where it is, whether it is used and how big it is; clear
empties it (and the key stays)."""
CACHE_EXAMPLES = ("python -m reactor cache info", "REACTOR_CACHE_DIR=/tmp/rc python -m reactor cache clear")


def _parser() -> ArgumentParser:
    parser = ArgumentParser(prog="python -m reactor", description=__doc__, examples=EXAMPLES)
    from . import __version__
    parser.add_argument("--version", action="version", version=f"%(prog)s (reactor-simd) {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    dump = sub.add_parser("dump", help="print the IR, optimized IR or assembly of a Function or kernel",
                          description=__doc__, examples=EXAMPLES)
    dump.add_argument("target", help="FILE.py:NAME or package.module:NAME")
    add_build_arguments(dump)
    explain = sub.add_parser("explain", help="each source line with its IR, assembly and cost; diffs; HTML",
                             description=EXPLAIN, examples=EXPLAIN_EXAMPLES)
    explain.add_argument("target", help="FILE.py:NAME or package.module:NAME")
    explain.add_argument("--html", metavar="OUT", help="write the page to OUT (an .html file)")
    explain.add_argument("--diff", action="append", default=[], metavar="KEY=VALUE",
                         help="compare with a build that differs so (fma=off, precision=relaxed, target=avx2, "
                              "width=8, opt=2); repeatable")
    explain.add_argument("--plumbing", action="store_true", help="also the loop control, tail and dispatcher")
    explain.add_argument("--brief", action="store_true", help="per line totals only, no instructions")
    explain.add_argument("--input", action="append", default=[], metavar="NAME=LO:HI|V1,V2,...",
                         help="sample values of an input (every input of the kernel): its loops' trip counts are "
                              "then measured on them; repeatable")
    explain.add_argument("--samples", type=positive_int, default=1 << 14, metavar="N",
                         help="elements of the sample run by --input (default 16384)")
    add_build_arguments(explain)
    explain.add_argument("--precision", help="full, relaxed (or GLSL's highp, mediump)")
    plan = sub.add_parser("plan", help="the cheapest precision per call site that changes no output",
                          description=PLAN, examples=PLAN_EXAMPLES)
    plan.add_argument("target", help="FILE.py:NAME or package.module:NAME (a @kernel ufunc)")
    plan.add_argument("--input", action="append", default=[], metavar="NAME=DOMAIN", help="an input's domain")
    plan.add_argument("--output", default="unorm8", metavar="FORMAT", help="what the scene stores (unorm8)")
    plan.add_argument("--samples", type=positive_int, default=1 << 18, metavar="N", help="rows of a sampled check")
    plan.add_argument("--save", metavar="FILE", help="write the plan as JSON (reactor.Plan.load reads it)")
    plan.add_argument("--verbose", action="store_true", help="each build of the search as it is made")
    glsl = sub.add_parser("glsl", help="render a GLSL fragment shader (or a Shadertoy one) to a PNG",
                          description=GLSL, examples=GLSL_EXAMPLES)
    glsl.add_argument("file", help="a GLSL fragment shader")
    glsl.add_argument("--size", required=True, metavar="WxH", help="the image's width and height in pixels")
    glsl.add_argument("--out", required=True, metavar="IMAGE", help="the PNG to write")
    glsl.add_argument("--shadertoy", action="store_true", help="a Shadertoy shader (mainImage)")
    glsl.add_argument("--time", type=float, default=0.0, metavar="T", help="iTime, seconds (Shadertoy)")
    cache = sub.add_parser("cache", help="show or empty the disk cache of compiled code",
                           description=CACHE, examples=CACHE_EXAMPLES)
    cache.add_argument("action", choices=("info", "clear"), help="info: where, how big, usable; clear: empty it")
    return parser


def _cache(action: str) -> int:
    from .jit import cache
    if action == "clear":
        print(f"removed {cache.clear()} entries from {cache.directory()}")
        return 0
    i = cache.info()
    print(f"directory  {i['directory'] or '(disabled)'}")
    print(f"usable     {'yes' if i['usable'] else 'no: ' + i['reason']}")
    print(f"entries    {i['objects']} objects, {i['recipes']} recipes")
    print(f"size       {i['bytes'] / 2**20:.1f} MiB of {i['bound'] / 2**20:.0f} MiB (REACTOR_CACHE_SIZE)")
    return 0


def _domain(text: str):
    from .planner import Range
    from .planner.domains import UNORM_BITS
    if text in UNORM_BITS or text == "float16":
        return text
    try:
        if ":" in text:
            lo, hi = text.split(":", 1)
            return Range(float(lo), float(hi))
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise ReactorError(f"--input: a domain is unorm8, unorm10, unorm16, float16, LO:HI or V1,V2,..., "
                           f"not {text!r}") from None


def _output(text: str):
    if ":" in text:
        kind, _, bound = text.partition(":")
        try:
            if kind in ("ulp", "abs"):
                return {kind: float(bound)}
        except ValueError:
            pass
        raise ReactorError(f"--output: a tolerance is ulp:N or abs:E, not {text!r}")
    return text


def _plan(args) -> int:
    from .planner import plan
    inputs = {}
    for spec in args.input:
        name, eq, domain = spec.partition("=")
        if not eq or not name:
            raise ReactorError(f"--input takes NAME=DOMAIN (x=unorm8, k=0.5,1,2, t=0:1), not {spec!r}")
        inputs[name] = _domain(domain)
    result = plan(load(args.target), inputs=inputs, output=_output(args.output), samples=args.samples,
                  progress=args.verbose)
    print(result)
    if args.save:
        result.save(args.save)
        print(f"wrote {args.save}")
    return 0


def _diff_options(specs: list[str]) -> dict:
    out: dict = {}
    for spec in specs:
        if "=" not in spec:
            raise ReactorError(f"--diff takes KEY=VALUE (fma=off, precision=relaxed, target=avx2), not {spec!r}")
        key, value = spec.split("=", 1)
        if key == "fma":
            out[key] = {"on": True, "off": False}.get(value)
            if out[key] is None:
                raise ReactorError(f"--diff fma= takes on or off, not {value!r}")
        elif key in ("width", "opt"):
            out[key] = int(value)
        elif key in ("precision", "target"):
            out[key] = value
        else:
            raise ReactorError(f"--diff: unknown setting {key!r} (fma, precision, target, width, opt)")
    return out


def _explain_inputs(specs: list[str], samples: int) -> dict | None:
    """``--input NAME=LO:HI`` (uniform samples) or ``NAME=V1,V2,...`` (drawn from the values), each
    ``samples`` long, by name (None without ``--input``); the draws are seeded (repeatable)."""
    import numpy as np
    if not specs:
        return None
    rng = np.random.default_rng(0)
    out = {}
    for spec in specs:
        name, eq, values = spec.partition("=")
        try:
            if not (eq and name):
                raise ValueError
            if ":" in values:
                lo, hi = (float(v) for v in values.split(":", 1))
                out[name] = rng.uniform(lo, hi, samples).astype(np.float32)
            else:
                out[name] = rng.choice(np.array([float(v) for v in values.split(",")]), samples)
        except ValueError:
            raise ReactorError(f"--input takes NAME=LO:HI or NAME=V1,V2,... (cx=-2:0.5, k=1,2,4), "
                               f"not {spec!r}") from None
    return out


def _explain(args) -> int:
    from .explain import explain
    target = load(args.target)
    chosen = {k: v for k, v in build_options(args).items() if v is not None}
    if args.precision:
        chosen["precision"] = args.precision
    inputs = _explain_inputs(args.input, args.samples)
    first = explain(target, plumbing=args.plumbing, inputs=inputs, **chosen)
    diff = None
    if args.diff:
        second = explain(target, plumbing=args.plumbing, inputs=inputs, **{**chosen, **_diff_options(args.diff)})
        diff = first.diff(second)
    if args.html:  # the page only: the text listing is in it
        print(f"wrote {first.write_html(args.html, diff)}")
        return 0
    print(first.text(instructions=not args.brief))
    if diff is not None:
        print("\n" + diff.text())
    return 0


def _glsl(args) -> int:
    from .spirv.render import render, write_png
    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
        if width < 1 or height < 1:
            raise ValueError
    except ValueError:
        raise ReactorError(f"--size: WIDTHxHEIGHT in pixels, as 320x180, not {args.size!r}") from None
    if not os.path.isfile(args.file):
        raise ReactorError(f"no such file: {args.file}")
    write_png(args.out, render(args.file, width, height, shadertoy=args.shadertoy, time=args.time))
    print(f"wrote {args.out} ({width}x{height})")
    return 0


def _main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    if args.command == "explain":
        return _explain(args)
    if args.command == "plan":
        return _plan(args)
    if args.command == "cache":
        return _cache(args.action)
    if args.command == "glsl":
        return _glsl(args)
    with options(**build_options(args)):
        print(text(load(args.target), args.what, args.everything))
    return 0


def main(argv: list[str] | None = None) -> int:
    """The command line; errors a user causes are one line and exit status 2 (see reactor.cli.run)."""
    return run(_main, argv)


if __name__ == "__main__":
    sys.exit(main())
