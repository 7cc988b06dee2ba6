"""Explain: a kernel's or Function's code, each instruction tied to the Python line that emitted it.

::

    e = reactor.explain(shade)                  # a kernel (ufunc) or a Function
    print(e.text())                             # per source line: Python, IR, assembly, cost
    e.write_html("shade.html")                  # three linked columns and the costs, one file
    print(e.diff(reactor.explain(shade, fma=False)).text())   # two builds, line by line
    reactor.explain(mandel, inputs=(cx, cy))    # loops' trip counts measured on these inputs

The body is traced again with source lines (``ModuleEmitter(lines=True)``: every
instruction's debug location is the user's line, and its column the group: the
user's own code, or a routine such as ``exp2`` emitted there), compiled with the
same settings (or those given), and read back from the optimized IR and the
assembly (``reactor.explain.listing``). A kernel shows its vector loop: the body
as it runs, W elements at a time; ``plumbing=True`` adds the rest (the loop
control, the width-1 tail body). The dataflow cost model
(``reactor.cost``) gives each line its operations by pipe, its share of the
throughput bound and whether it is on the critical path.

Each line is weighed by how often it runs per vector iteration (``reactor.cost.lines``):
the body of a run-time ``while``/``for`` as many times as its loop iterates. With
``inputs=`` (sample arguments, as the kernel would be called) the trip counts are
measured: the loop runs on them with a counter in every block (``reactor.explain.profile``);
without, they are estimated (a counter against a constant bound: that bound; else a stated
assumption). ``Explanation.loops`` and the text's header give every loop's line, its
iterations per vector and whether they were measured or estimated.
"""
from __future__ import annotations

import collections
import re
import dataclasses
import typing

from ..cost.lines import line_costs, runs_text, summary_text
from ..errors import ReactorError
from .listing import Instruction, parse_asm, parse_ir, source_line

__all__ = ["explain", "Explanation", "Line", "Diff", "LoopCount"]


@dataclasses.dataclass(frozen=True)
class LoopCount:
    """A loop of a kernel's vector iteration: its source lines, its iterations per vector
    iteration (``width`` elements) and ``how`` they are known ("measured" or "estimated")."""

    file: str | None
    first: int
    last: int
    trips: float
    how: str
    detail: str
    width: int
    elements: int = 0  # the sample's size when measured

    def text(self) -> str:
        """"loop at mandel.py:9 (to line 16): 29.6 iterations a vector (16 lanes), measured on ..."."""
        to = f" (to line {self.last})" if self.last != self.first else ""
        on = (f"measured on the given inputs ({self.elements} elements)" if self.how == "measured"
              else f"estimated: {self.detail}")
        return (f"loop at {_short(self.file)}:{self.first}{to}: {self.trips:.1f} iterations a vector "
                f"({self.width} lanes), {on}")


@dataclasses.dataclass
class Line:
    """One source line (and group) of a build: its IR and machine instructions and their cost."""

    file: str | None
    line: int
    group: str  # "" for the user's own code, else the routine's name
    ir: list[Instruction] = dataclasses.field(default_factory=list)
    asm: list[Instruction] = dataclasses.field(default_factory=list)
    cost: dict = dataclasses.field(default_factory=dict)  # by the cost model: ops, slots, share, critical

    @property
    def source(self) -> str:
        return source_line(self.file, self.line) if self.line else "(reactor: loop control, layout, tail)"

    @property
    def label(self) -> str:
        where = f"{_short(self.file)}:{self.line}" if self.line else "plumbing"
        return where + (f" [{self.group}]" if self.group else "")

    @property
    def key(self) -> str:
        return f"{self.file}:{self.line}:{self.group}"


@dataclasses.dataclass
class Explanation:
    """The lines of one build, in source order, with totals."""

    name: str
    settings: str
    lines: list[Line]
    costs: dict  # the whole region: the model's prediction (empty without a model)
    ir_text: str
    assembly: str
    loops: list[LoopCount] = dataclasses.field(default_factory=list)

    def text(self, instructions: bool = True) -> str:
        """A terminal view: each line's Python, its IR and assembly, and its cost (weighted by how
        often the line runs; the loops' trip counts, measured or estimated, in the header)."""
        out = [f"{self.name}: {self.settings}"]
        if self.costs:
            out.append(summary_text(self.costs))
        out.extend(lp.text() for lp in self.loops)
        for row in self.lines:
            cost = _cost_text(row.cost)
            out.append("")
            out.append(f"{row.label:<28} {row.source.strip()}")
            out.append(f"{'':<28} {len(row.ir)} IR, {len(row.asm)} machine instructions{cost}")
            if instructions:
                out.extend(f"    ir   {i.text}" for i in row.ir)
                out.extend(f"    asm  {i.text}" for i in row.asm)
        return "\n".join(out)

    def html(self, diff: "Diff | None" = None) -> str:
        from .html import page
        return page(self, diff)

    def write_html(self, path: str, diff: "Diff | None" = None) -> str:
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.html(diff))
        return path

    def diff(self, other: "Explanation") -> "Diff":
        """Two builds of one body, line by line (the lines whose machine code differs first)."""
        return Diff(self, other)

    def line(self, line: int, group: str = "") -> Line:
        for row in self.lines:
            if row.line == line and row.group == group:
                return row
        raise KeyError((line, group))


#: register numbers (%ymm3 -> %ymm), general registers and local labels, left out of a diff
_NORMALIZE = re.compile(r"%([xyz]mm)\d+|%[re]?[a-z0-9]+[dwb]?\b(?<![xyz]mm)|\.L[A-Za-z_]*\d+(?:_\d+)?")


class Diff:
    """Two explanations side by side: per line, both builds' machine code."""

    def __init__(self, a: Explanation, b: Explanation) -> None:
        self.a, self.b = a, b
        keys = list(dict.fromkeys([r.key for r in a.lines] + [r.key for r in b.lines]))
        rows_a, rows_b = {r.key: r for r in a.lines}, {r.key: r for r in b.lines}
        self.rows = [(rows_a.get(k), rows_b.get(k)) for k in keys]

    @staticmethod
    def _ops(row: Line | None) -> collections.Counter:
        return collections.Counter(i.text.split()[0] for i in row.asm) if row else collections.Counter()

    @staticmethod
    def _code(row: Line | None) -> list[str]:
        """The line's instructions with register numbers and labels left out (their class kept:
        xmm, ymm, zmm), so a change of width, operand or order shows, an allocation does not."""
        if row is None:
            return []
        return sorted(_NORMALIZE.sub(lambda m: m.group(1) or ".L", i.text) for i in row.asm)

    def differs(self, x: Line | None, y: Line | None) -> bool:
        return self._code(x) != self._code(y)

    def changed(self) -> list[tuple[Line | None, Line | None]]:
        return [(x, y) for x, y in self.rows if self.differs(x, y)]

    def text(self) -> str:
        out = [f"A: {self.a.settings}", f"B: {self.b.settings}"]
        for x, y in self.rows:
            row = x or y
            assert row is not None
            ops_a, ops_b = self._ops(x), self._ops(y)
            differs = self.differs(x, y)
            out.append(f"{'≠ ' if differs else '  '}{row.label:<28} {row.source.strip()}")
            if differs:
                same = " (the same operations; operands or registers differ)" if ops_a == ops_b else ""
                out.append(f"      A {sum(ops_a.values()):3d}: {_op_list(ops_a)}{same}")
                out.append(f"      B {sum(ops_b.values()):3d}: {_op_list(ops_b)}")
        return "\n".join(out)


def explain(obj: typing.Any, /, *, plumbing: bool = False, inputs: typing.Any = None,
            **options: typing.Any) -> Explanation:
    """Explain a kernel (its ufunc or ``Kernel``) or a ``Function`` built with its own settings,
    or with ``options`` (fma, precision, target, width, opt) instead. ``inputs``: sample arguments
    of a kernel (a sequence of arrays, one per input, or a dict by parameter name; broadcast
    together), on which its loops' trip counts are measured; without them they are estimated."""
    from ..jit.compiler import listing
    from ..kernels.kernel import Kernel, kernel_of
    from ..runtime.function import Function, Module

    kern = obj if isinstance(obj, Kernel) else None
    if kern is None and not isinstance(obj, Function):
        try:
            kern = kernel_of(obj)
        except (ReactorError, TypeError):
            raise ReactorError(f"explain takes a reactor kernel (a ufunc made by @kernel) or a Function, "
                               f"not {obj!r}") from None
    if kern is not None:
        if options:
            from ..kernels.kernel import build_kernel
            kern = kernel_of(build_kernel(kern.body, name=kern.name, **options))
        module = kern.traced_with_lines()
        build, name, region = kern.build, kern.name, f"{kern.name}.loop"
    else:
        if inputs is not None:
            raise ReactorError("explain(inputs=...) measures a kernel's loops; a Function has no vector loop")
        build = obj.build_settings(**options)
        module = Module([obj]).build(build, lines=True)
        name, region = obj.name, None
    optimized, assembly = listing(module.text, build.target, build.opt)
    assert module.lines is not None
    groups = module.lines.groups
    ir_fns = parse_ir(optimized)
    lines = _lines(ir_fns, parse_asm(assembly), groups, region, plumbing)
    counts, elements = None, 0
    if inputs is not None and kern is not None:
        from .profile import measure
        counts, elements = measure(kern, optimized, module.imports, inputs)
    costs = _apply_costs(lines, optimized, region, build.width, counts)
    loops = _loops(costs.get("loops", []), ir_fns.get(region or "", []), build.width, elements)
    return Explanation(name, build.describe(), lines, costs, optimized, assembly, loops)


def _loops(found: list[dict], instructions: list[Instruction], width: int, elements: int) -> list[LoopCount]:
    """The cost model's loops (``reactor.cost.lines.Loop`` as dicts) with the source lines of
    their instructions (the first to the last user's line inside the loop)."""
    out = []
    for lp in found:
        inside = [i for i in instructions if i.block in lp["blocks"] and i.line]
        if not inside:
            continue
        file = collections.Counter(i.file for i in inside).most_common(1)[0][0]
        numbers = [i.line for i in inside if i.file == file]
        out.append(LoopCount(file, min(numbers), max(numbers), lp["trips"], lp["how"], lp["detail"], width,
                             elements if lp["how"] == "measured" else 0))
    return out


def _lines(ir_fns, asm_fns, groups, region, plumbing) -> list[Line]:
    rows: dict[tuple, Line] = {}

    def add(ins: Instruction, which: str) -> None:
        if ins.tail and not plumbing:
            return
        if ins.line == 0 and not plumbing:
            return
        key = (ins.file, ins.line, groups[ins.group] if ins.group < len(groups) else "?")
        row = rows.get(key)
        if row is None:
            row = rows[key] = Line(*key)
        getattr(row, which).append(ins)

    for fns, which in ((ir_fns, "ir"), (asm_fns, "asm")):
        for fname, instructions in fns.items():
            if region is not None and fname != region and not plumbing:
                continue
            for ins in instructions:
                add(ins, which)
    order = sorted(rows.values(), key=lambda r: (r.line == 0, r.file or "", r.line, groups.index(r.group)
                                                 if r.group in groups else 99))
    return order


def _apply_costs(lines: list[Line], optimized: str, region: str | None, width: int,
                 counts: dict[str, int] | None = None) -> dict:
    """Give each line its cost (operations by class, ``busy``: pipe time a vector iteration, each
    instruction weighed by its executions per iteration, ``share`` of the total, ``runs``: the
    most any of its instructions runs a vector); the model's summary, with the loops."""
    if region is None:
        return {}
    per_instruction, summary = line_costs(optimized, region, width, counts=counts)
    by_text = collections.defaultdict(list)
    for text, cost in per_instruction:
        by_text[(cost["block"], text.strip())].append(cost)
    total = summary.get("busy", 0) or 1
    for row in lines:
        ops: collections.Counter = collections.Counter()
        busy, critical, runs = 0.0, False, 0.0
        for ins in row.ir:
            for cost in by_text.get((ins.block, ins.text.strip()), [])[:1]:
                if cost.get("class"):
                    ops[cost["class"]] += 1
                    busy += cost.get("busy", 0.0)
                    runs = max(runs, cost.get("weight", 1.0))
                critical = critical or cost.get("critical", False)
        if ops:
            row.cost = {"ops": dict(ops), "busy": busy, "share": busy / total, "critical": critical, "runs": runs}
    return summary


def _short(path: str | None) -> str:
    import os
    return os.path.basename(path) if path else "?"


def _op_list(ops: collections.Counter) -> str:
    return ", ".join(f"{n} {op}" if n > 1 else op for op, n in sorted(ops.items(), key=lambda kv: (-kv[1], kv[0])))


def _cost_text(cost: dict) -> str:
    if not cost:
        return ""
    ops = ", ".join(f"{n} {c}" for c, n in sorted(cost["ops"].items(), key=lambda kv: -kv[1]))
    return (f"; {ops}{runs_text(cost)}; {cost['share']:.0%} of the work"
            f"{'; on the critical path' if cost['critical'] else ''}")

