"""Measured trip counts: a kernel's vector loop run on sample inputs with a counter in every block.

``reactor.explain(kernel, inputs=...)`` weighs each source line by how often it runs. The
counts come from the optimized IR it explains: every block of one vector iteration
(``reactor.cost.lines.region``: ``vec.body`` and the blocks on its way back to itself) gets
an increment of its own 64-bit counter, the module is compiled again (not cached) and its
``<name>.loop`` is called once, as NumPy would call it, on the given inputs made contiguous.
The kernel's own machine code is not touched; the counting build differs from it only by
the counters.
"""
from __future__ import annotations

import ctypes
import re
import typing

import numpy as np

from ..cost.lines import region_blocks
from ..errors import ReactorError

_LABEL = re.compile(r'^("?)([^\s":]+)\1:')


def instrument(optimized_ir: str, function: str, blocks: typing.Sequence[str], address: int) -> str:
    """``optimized_ir`` with, at the top of each of ``blocks`` of ``function`` (after its phis),
    an increment of the i64 at ``address + 8 * k`` for the k-th block."""
    index = {name: k for k, name in enumerate(blocks)}
    out: list[str] = []
    inside, pending = False, None
    for raw in optimized_ir.splitlines():
        if raw.startswith("define") and (f'@"{function}"(' in raw or f"@{function}(" in raw):
            inside = True
        elif inside and raw.startswith("}"):
            inside = False
        m = _LABEL.match(raw) if inside else None
        if m:
            pending = index.get(m.group(2))
            out.append(raw)
            continue
        body = raw.strip()
        if pending is not None and body and not body.startswith(";") and " = phi " not in body:
            out.extend(_increment(pending, address + 8 * pending))
            pending = None
        out.append(raw)
    return "\n".join(out) + "\n"


def _increment(k: int, address: int) -> list[str]:
    where = f"ptr inttoptr (i64 {address} to ptr)"
    return [f"  %__count{k} = load i64, {where}, align 8",
            f"  %__count{k}.next = add i64 %__count{k}, 1",
            f"  store i64 %__count{k}.next, {where}, align 8"]


def _operands(kern, inputs) -> list[np.ndarray]:
    """The inputs as contiguous arrays of the kernel's dtypes, broadcast together, and its outputs."""
    if any(o.uniform or o.vector for o in kern.ins + kern.outs):
        raise ReactorError(f"explain(inputs=...) measures kernels of plain element operands; "
                           f"'{kern.name}' has vector, table or texture operands (its loops are estimated "
                           f"without inputs)")
    if isinstance(inputs, dict):
        names = list(kern.signature.names)
        missing = [n for n in names if n not in inputs]
        if missing:
            raise ReactorError(f"explain(inputs=...): no values for {', '.join(missing)} (inputs: {', '.join(names)})")
        unknown = [n for n in inputs if n not in names]
        if unknown:
            raise ReactorError(f"explain(inputs=...): '{kern.name}' has no input {', '.join(map(repr, unknown))} "
                               f"(inputs: {', '.join(names)})")
        inputs = [inputs[n] for n in names]
    inputs = list(inputs)
    if len(inputs) != len(kern.ins):
        raise ReactorError(f"explain(inputs=...): '{kern.name}' takes {len(kern.ins)} inputs, {len(inputs)} given")
    arrays = np.broadcast_arrays(*[np.asarray(a, dtype=o.kind.dtype) for a, o in zip(inputs, kern.ins)])
    ins = [np.ascontiguousarray(a.ravel()) for a in arrays]
    return ins + [np.empty(ins[0].size, dtype=o.kind.dtype) for o in kern.outs]


def measure(kern, optimized_ir: str, imports: dict[str, int] | None, inputs) -> tuple[dict[str, int], int]:
    """(each block's executions in one vector iteration's region, elements run) when ``kern``'s
    loop (the function ``<name>.loop`` of ``optimized_ir``) runs on ``inputs`` (a sequence of
    arrays, one per input, or a dict by parameter name; broadcast together)."""
    from ..jit.compiler import CompiledCode

    if not kern.build.target.runnable:
        raise ReactorError(f"explain(inputs=...) runs the kernel: target '{kern.build.target.name}' cannot run "
                           f"on this CPU")
    operands = _operands(kern, inputs)
    n = operands[0].size
    if n < kern.build.width:
        raise ReactorError(f"explain(inputs=...): give at least {kern.build.width} elements (one vector), not {n}")
    function = f"{kern.name}.loop"
    blocks = region_blocks(optimized_ir, function)
    counters = np.zeros(len(blocks), dtype=np.int64)
    text = instrument(optimized_ir, function, blocks, counters.ctypes.data)
    code = CompiledCode(text, kern.build.target, kern.build.opt, (function,), False, imports)
    loop = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)(
        code.address(function))
    args = (ctypes.c_void_p * len(operands))(*[a.ctypes.data for a in operands])
    dims = (ctypes.c_ssize_t * 1)(n)
    steps = (ctypes.c_ssize_t * len(operands))(*[a.itemsize for a in operands])
    loop(args, dims, steps, ctypes.addressof(kern.config))
    return {name: int(c) for name, c in zip(blocks, counters)}, n
