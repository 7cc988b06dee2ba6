"""Reading a kernel's assembly for ``python -m routines dump --what asm``: its core, its constants' values
and the algorithm's steps.

* :func:`constant_pool` decodes the constant pool (``.LCPI0_3:`` followed by ``.long``, ``.quad``,
  ``.short``, ``.byte``, ``.zero`` directives) into bytes;
* :func:`core` finds the vector loop of a function: of the loops (a label and a later branch back
  to it), the one with the most packed instructions on the widest vector registers -- the
  body as it runs, W lanes at a time, not the prologue, the scalar tail or the epilogue;
* :func:`annotate` writes the core with every constant it reads (through a ``.LCPI`` reference,
  or a register loaded from one before the loop and not written in it) shown by value, and
  each instruction's step: recognised from what the instruction is (a rounding or
  ``VREDUCEPS``: range reduction; ``VSCALEFPS`` or a shift by the exponent's position:
  reconstruction; compares, classifications and masked blends: special cases), from its
  constants (those of a polynomial in ``polynomials``, routines' own tables: that polynomial,
  Horner's scheme when its multiply-adds form one chain), and otherwise from the data it
  reads (an instruction continues the latest step of the instructions that produced its
  operands). Nothing is listed per routine.
"""
from __future__ import annotations

import dataclasses
import re
import struct
from collections.abc import Iterable, Sequence

import numpy as np

_POOL_LABEL = re.compile(r"^(\.LCPI\d+_\d+):")
_DIRECTIVE = re.compile(r"^\s*\.(byte|short|value|long|int|word|quad|xword|zero|space)\s+(.*?)\s*(?:[#@].*)?$")
_REF = re.compile(r"\.LCPI\d+_\d+")
_LABEL = re.compile(r"^([.\w$]+):")
_JUMP = re.compile(r"^\s*(j\w+|b(?:\.\w+)?|cbn?z|tbn?z)\s+.*?([.\w$]+)\s*$")
_VREG = re.compile(r"%([xyz])mm(\d+)|\b([qvsdhb])(\d+)(?:\.\d*[bhsd])?\b")
_SIZES = {"byte": 1, "short": 2, "value": 2, "long": 4, "int": 4, "word": 4, "quad": 8, "xword": 8}

#: the steps, in the order an algorithm of the library takes them (an instruction that reads
#: several steps' results continues the latest)
STEPS = ("range reduction", "polynomial", "reconstruction", "special cases")
_SEEDS = (  # (mnemonic pattern, step): what an instruction is, whatever its operands
    (r"^v?(reduce|rndscale|round|getexp|getmant)|^frint|^v?cvtt?(ps2dq|ps2udq|pd2dq|ps2qq)|^fcvt[zn][su]",
     "range reduction"),
    (r"^v?scalef|^fscale", "reconstruction"),
    (r"^v?(cmp|fpclass|fixupimm|blendv|blendm|ptestm|ptestnm)|^k(or|and|andn|not|xor|test|ortest)|^fcm|^bsl|^bi[tf]",
     "special cases"),
)


@dataclasses.dataclass
class Line:
    """One instruction of the core: its text, the constants it reads and its step."""

    text: str
    constants: list[tuple[str, str]] = dataclasses.field(default_factory=list)  # (register or label, value)
    step: str = ""


def constant_pool(assembly: str) -> dict[str, bytes]:
    """The bytes behind every ``.LCPI`` label of ``assembly`` (little-endian, as the directives say)."""
    pool: dict[str, bytes] = {}
    label = None
    for raw in assembly.splitlines():
        m = _POOL_LABEL.match(raw)
        if m:
            label = m.group(1)
            pool[label] = b""
            continue
        if label is None:
            continue
        d = _DIRECTIVE.match(raw)
        if d:
            pool[label] += _directive_bytes(d.group(1), d.group(2))
        elif raw.strip() and not raw.strip().startswith((".p2align", ".align", "#", "//", ";")):
            label = None
    return pool


def _directive_bytes(kind: str, args: str) -> bytes:
    if kind in ("zero", "space"):
        count, _, fill = args.partition(",")
        return bytes([int(fill or "0", 0) & 0xFF]) * int(count, 0)
    size = _SIZES[kind]
    return b"".join((int(a.strip(), 0) & ((1 << 8 * size) - 1)).to_bytes(size, "little")
                    for a in args.split(",") if a.strip())


def value_text(data: bytes, kind: str) -> str:
    """A constant's value as the instruction reads it: ``kind`` "f32", "f64", "i32" or "i64"; one
    element ``1.442695f (0x3fb8aa3b)``, equal elements ``{16 x 1.0f (0x3f800000)}``, else the list."""
    size = 8 if kind in ("f64", "i64") else 4
    if not data or len(data) % size:
        return data.hex() or "?"
    fmt = {"f32": "<f", "f64": "<d", "i32": "<I", "i64": "<Q"}[kind]
    words = [data[k:k + size] for k in range(0, len(data), size)]

    def one(word: bytes) -> str:
        bits = int.from_bytes(word, "little")
        if kind.startswith("f"):
            v = struct.unpack(fmt, word)[0]
            text = str(np.float32(v)) + "f" if kind == "f32" else repr(v)
            return f"{text} (0x{bits:0{2 * size}x})"
        return f"0x{bits:0{2 * size}x}" + (f" ({bits})" if bits < 1 << 16 else "")
    if len(set(words)) == 1:
        return one(words[0]) if len(words) == 1 else f"{{{len(words)} x {one(words[0])}}}"
    shown = ", ".join(one(w) for w in words[:8])
    return f"{{{shown}{', ...' if len(words) > 8 else ''}}}"


def element_kind(mnemonic: str) -> str:
    """How an instruction reads a constant: float32 ("f32"), float64, int32 or int64 elements."""
    m = mnemonic.lower()
    if m.startswith(("vp", "p", "vmovdq", "movdq")):
        return "i64" if m.endswith("q") and not re.search(r"(2u?dq|movdq)$", m) else "i32"
    if re.search(r"(pd|sd)$", m) or "broadcastsd" in m:
        return "f64"
    return "f32"


def function_lines(assembly: str, name: str) -> list[str]:
    """The lines of function ``name`` in ``assembly`` (its label to ``.Lfunc_end``), [] if absent."""
    lines = assembly.splitlines()
    start = next((i for i, l in enumerate(lines) if l.startswith((f"{name}:", f'"{name}":'))), None)
    if start is None:
        return []
    end = next((i for i in range(start, len(lines)) if lines[i].startswith(".Lfunc_end")), len(lines) - 1)
    return lines[start:end + 1]


def _is_instruction(raw: str) -> bool:
    s = raw.strip()
    return bool(s) and raw[0] in "\t " and not s.startswith((".", "#", "//", ";"))


def _width_class(text: str) -> int:
    """512, 256 or 128 for the widest x86 vector register an instruction names (AArch64's q/v: 128)."""
    classes = [{"z": 512, "y": 256, "x": 128}[m.group(1)] if m.group(1) else 128 for m in _VREG.finditer(text)]
    return max(classes, default=0)


def core(lines: Sequence[str]) -> tuple[int, int] | None:
    """(first, last) line index of the vector loop in a function's ``lines``: the loop (a label and
    the last branch back to it) with the most packed instructions on the widest registers used."""
    labels = {m.group(1): i for i, l in enumerate(lines) if (m := _LABEL.match(l))}
    loops = []
    for j, raw in enumerate(lines):
        m = _JUMP.match(raw)
        if m and m.group(2) in labels and labels[m.group(2)] < j:
            loops.append((labels[m.group(2)], j))
    if not loops:
        return None
    widest = max((_width_class(l) for l in lines if _is_instruction(l)), default=0)

    def score(span: tuple[int, int]) -> tuple[int, int]:
        body = [l for l in lines[span[0]:span[1] + 1] if _is_instruction(l)]
        packed = sum(1 for l in body if _width_class(l) == widest and not re.search(r"\s\w+s[sd]\s", l))
        return packed, -(span[1] - span[0])
    best = max(loops, key=score)
    return best if score(best)[0] > 0 else None


def _entry(lines: Sequence[str], span: tuple[int, int]) -> int:
    """Where the loop is entered: the label inside it that the jump just before it goes to (LLVM
    rotates loops so), else its first line."""
    before = next((l for l in reversed(lines[:span[0]]) if _is_instruction(l)), "")
    m = _JUMP.match(before)
    if m and m.group(1) in ("jmp", "b"):
        for i in range(span[0], span[1] + 1):
            if lines[i].startswith(f"{m.group(2)}:"):
                return i
    return span[0]


def _operands(text: str) -> tuple[str, list[str]]:
    """(mnemonic, operands) of an instruction (commas inside parentheses and braces kept)."""
    parts = text.strip().split(None, 1)
    ops, depth, cur = [], 0, ""
    for ch in parts[1] if len(parts) > 1 else "":
        depth += ch in "([{" and 1 or (ch in ")]}" and -1 or 0)
        if ch == "," and depth == 0:
            ops.append(cur.strip())
            cur = ""
        else:
            cur += ch
    if cur.strip():
        ops.append(cur.strip())
    return parts[0], ops


def _reg(operand: str) -> str | None:
    """The vector register an operand is (``%zmm3``, ``v3.4s``, ``q3`` -> "v3"), else None."""
    m = _VREG.fullmatch(operand.split("{")[0].strip())
    return f"v{m.group(2) or m.group(4)}" if m else None


def _destination(ops: list[str], x86: bool) -> str | None:
    if not ops:
        return None
    return _reg(ops[-1] if x86 else ops[0])


def _sources(ops: list[str], x86: bool) -> list[str]:
    rest = ops[:-1] if x86 else ops[1:]
    return [r for r in (_reg(o) for o in rest) if r]


def _reads_destination(mnemonic: str, text: str = "", x86: bool = True) -> bool:
    """Instructions that read their destination too: FMAs (x86's three-operand forms, AArch64's
    FMLA/FMLS), AVX-512 merge masking (``{%k1}`` without ``{z}``), legacy SSE's two-operand
    arithmetic (``mulps %xmm1, %xmm0``: xmm0 *= xmm1)."""
    if re.match(r"^v?f(n?m(add|sub))|^fml[as]", mnemonic):
        return True
    if x86 and "{%k" in text and "{z}" not in text:
        return True
    return x86 and not mnemonic.startswith(("v", "mov", "j", "cvt", "lea")) and len(_operands(text)[1]) == 2 \
        and bool(_width_class(text))


def annotate(lines: Sequence[str], pool: dict[str, bytes],
             polynomials: Iterable[tuple[str, Sequence[float]]] = ()) -> tuple[list[Line], list[str]] | None:
    """(the core's instructions annotated, a summary of its steps and constants) for a function's
    ``lines``; ``polynomials``: (name, float32 coefficients) of the polynomials to recognise.
    None if the function has no vector loop."""
    span = core(lines)
    if span is None:
        return None
    x86 = any("%" in l for l in lines if _is_instruction(l))
    held: dict[str, tuple[str, str]] = {}  # register -> (label, value) loaded before the loop
    names: dict[str, str] = {}  # register -> as written (%zmm3, v3.4s)
    gpr: dict[str, int] = {}  # AArch64: general registers set from immediates (mov/movk)
    for raw in lines[:span[0]]:
        if not _is_instruction(raw):
            continue
        mnemonic, ops = _operands(raw)
        dest = _destination(ops, x86)
        refs = _REF.findall(raw)
        built = None if x86 else _materialized(mnemonic, ops, gpr)
        if built is not None:
            held[built[0]] = (f"{mnemonic} before the loop", value_text(built[1], "f32"))
            names[built[0]] = ops[0]
            continue
        if dest:
            held.pop(dest, None)
            if refs and refs[0] in pool:
                held[dest] = (refs[0], value_text(pool[refs[0]], element_kind(mnemonic)))
                names[dest] = (ops[-1] if x86 else ops[0]).split("{")[0].strip()
    entry = _entry(lines, span)
    body = list(lines[entry:span[1] + 1]) + list(lines[span[0]:entry])  # from where the loop is entered
    written = {d for raw in body if _is_instruction(raw) for d in [_destination(_operands(raw)[1], x86)] if d}
    held = {r: v for r, v in held.items() if r not in written}
    out = [_read(raw, held, pool, x86) for raw in body]
    summary = _steps(out, {names[r]: v for r, v in held.items()}, polynomials, x86)
    return out, summary


def _immediate(text: str) -> int | None:
    m = re.fullmatch(r"#(-?(?:0x[0-9a-f]+|\d+))", text.strip(), re.I)
    return int(m.group(1), 0) if m else None


def _materialized(mnemonic: str, ops: list[str], gpr: dict[str, int]) -> tuple[str, bytes] | None:
    """AArch64 builds constants without a pool: ``mov w11, #41554; movk w11, #14624, lsl #16;
    dup v0.4s, w11``, ``fmov v17.4s, #1.0``, ``movi``/``mvni`` with a shift. Follows the general
    registers in ``gpr``; (vector register, one element's bytes) when a vector register gets one."""
    if len(ops) < 2:
        return None
    dest, imm = ops[0], _immediate(ops[1])
    shift = re.fullmatch(r"(lsl|msl)\s+#(\d+)", ops[2].strip()) if len(ops) > 2 else None
    if mnemonic == "mov" and re.fullmatch(r"[wx]\d+", dest) and imm is not None:
        gpr[dest[1:]] = imm & 0xFFFFFFFF
    elif mnemonic == "movk" and re.fullmatch(r"[wx]\d+", dest) and imm is not None and dest[1:] in gpr:
        at = int(shift.group(2)) if shift else 0
        gpr[dest[1:]] = (gpr[dest[1:]] & ~(0xFFFF << at) | imm << at) & 0xFFFFFFFF
    elif re.fullmatch(r"[wx]\d+", dest):
        gpr.pop(dest[1:], None)
    vreg = _reg(dest)
    if vreg is None or not dest.endswith(".4s"):
        return None
    if mnemonic == "dup" and re.fullmatch(r"w\d+", ops[1]) and ops[1][1:] in gpr:
        return vreg, gpr[ops[1][1:]].to_bytes(4, "little")
    if mnemonic == "fmov" and re.fullmatch(r"#-?[\d.]+(e[-+]?\d+)?", ops[1]):
        return vreg, struct.pack("<f", float(ops[1][1:]))
    if mnemonic in ("movi", "mvni") and imm is not None:
        at = int(shift.group(2)) if shift else 0
        value = imm << at | ((1 << at) - 1 if shift and shift.group(1) == "msl" else 0)
        return vreg, ((~value if mnemonic == "mvni" else value) & 0xFFFFFFFF).to_bytes(4, "little")
    return None


def _read(raw: str, held: dict, pool: dict, x86: bool) -> Line:
    """An instruction with the constants it reads: pool references and registers holding one."""
    line = Line(raw)
    if not _is_instruction(raw):
        return line
    mnemonic, ops = _operands(raw)
    kind = element_kind(mnemonic)
    for ref in _REF.findall(raw):
        line.constants.append((ref, value_text(pool[ref], kind) if ref in pool else "not in the listing"))
    written = ops[:-1] if x86 else ops[1:]
    if _reads_destination(mnemonic, raw, x86):
        written = ops
    for operand in written:
        reg = _reg(operand)
        if reg in held:
            line.constants.append((operand.split("{")[0].strip(), f"{held[reg][1]} ({held[reg][0]})"))
    return line


def _floats(value: str) -> set[float]:
    """The float32 values written in a constant's text (``0.055503443f``)."""
    return {float(np.float32(v)) for v in re.findall(r"(?<![\w.])(-?(?:\d+\.?\d*(?:e[-+]?\d+)?|inf|nan))f\b", value)}


def _steps(out: list[Line], held: dict, polynomials, x86: bool) -> list[str]:
    """Give each instruction of the core its step (see the module docstring); the summary lines."""
    polys = [(name, [float(np.float32(c)) for c in coeffs]) for name, coeffs in polynomials]
    used = set().union(*(_floats(v) for line in out for _, v in line.constants)) if out else set()
    found = [(name, set(c)) for name, c in polys if len(c) >= 2 and set(c) <= used]
    found = [(n, c) for n, c in found if not any(c < other for _, other in found)]  # the largest match
    producer: dict[str, str] = {}
    chains: dict[str, list[int]] = {n: [] for n, _ in found}
    for rounds in range(2):  # twice: a value carried round the loop is read before it is written
        for k, line in enumerate(out):
            if _is_instruction(line.text):
                line.step = _step(k, line, found, producer, chains if rounds else None, x86)
    for line in out:
        if line.step.startswith("polynomial ") and line.step in {f"polynomial {n}" for n in chains}:
            name = line.step[len("polynomial "):]
            coeffs = next(c for n, c in polys if n == name)
            line.step = f"polynomial {name} ({_scheme(out, chains[name], x86)}, degree {len(coeffs) - 1})"
    counts: dict[str, int] = {}
    for line in out:
        if line.step:
            counts[line.step] = counts.get(line.step, 0) + 1
    steps = "; ".join(f"{s} ({n})" for s, n in sorted(counts.items(), key=lambda kv: _order(kv[0]))
                      if s not in ("loop control",))
    summary = [f"steps: {steps}" if steps else "steps: none recognised"]
    if held:
        summary.append("constants held in registers through the loop (loaded before it):")
        summary += [f"  {r} = {v} ({label})" for r, (label, v) in
                    sorted(held.items(), key=lambda kv: int(re.sub(r"\D", "", kv[0]) or 0))]
    return summary


def _step(k: int, line: Line, found, producer: dict[str, str], chains: dict | None, x86: bool) -> str:
    """The step of the ``k``-th instruction (see the module docstring); records the step of the
    register it writes in ``producer`` and, given ``chains``, ``k`` in its polynomial's chain."""
    mnemonic, ops = _operands(line.text)
    values = set().union(*(_floats(v) for _, v in line.constants)) if line.constants else set()
    vector = bool(_width_class(line.text)) or mnemonic.startswith("k")
    step = next((s for pattern, s in _SEEDS if vector and re.search(pattern, mnemonic)), "")
    poly = next((n for n, c in found if values & c), None)
    if poly and not step:
        step = f"polynomial {poly}"
        if chains is not None:
            chains[poly].append(k)
    if re.match(r"^(v?ps[lr]l[dq]|shl|ushr)", mnemonic) and re.search(r"\$?#?(23|52)\b", line.text):
        step = "reconstruction"  # a shift by the exponent field's position
    reads_dest = _reads_destination(mnemonic, line.text, x86)
    srcs = _sources(ops, x86) + ([_destination(ops, x86) or ""] if reads_dest else [])
    memory = [o for o in ops if ("(" in o or "[" in o) and not _REF.search(o)]
    if not step and not vector:
        step = "loop control"
    if not step and memory and re.match(r"^v?(mov|ld|st|broadcast)", mnemonic):
        stored = ops[-1] if x86 else (ops[1] if len(ops) > 1 and mnemonic.startswith("st") else "")
        step = "store" if memory[-1] == stored else "load"
    if not step:  # continues the latest step among what it reads (loads and stores are no step)
        before = [producer[r] for r in srcs if _order(producer.get(r, "")) > 0]
        step = max(before, key=_order, default="")
    dest = _destination(ops, x86)
    if dest:
        producer[dest] = step
    return step


def _order(step: str) -> int:
    """Where a step comes in :data:`STEPS` (a polynomial's name included); others first."""
    for k, s in enumerate(STEPS):
        if step.startswith(s):
            return k + 1
    return 0


def _scheme(out: list[Line], members: list[int], x86: bool) -> str:
    """"Horner" when the polynomial's multiply-adds form one chain (each reads the previous one's
    result), else "Estrin or split" (several independent products)."""
    fmas = [k for k in members if re.match(r"^v?f(n?m(add|sub))|^fml[as]|^fmadd", _operands(out[k].text)[0])]
    if len(fmas) < 2:
        return "Horner"
    dests = [_destination(_operands(out[k].text)[1], x86) for k in fmas]
    return "Horner" if len(set(dests)) == 1 or all(
        dests[i] in _sources(_operands(out[fmas[i + 1]].text)[1], x86) or dests[i] == dests[i + 1]
        for i in range(len(fmas) - 1)) else "Estrin or split"


def render(lines: Sequence[str], pool: dict[str, bytes], polynomials: Iterable[tuple[str, Sequence[float]]],
           name: str, width: int) -> str | None:
    """The core of function ``name`` first, annotated, then the whole function with its pool
    references annotated; None if it has no vector loop."""
    found = annotate(lines, pool, polynomials)
    if found is None:
        return None
    core_lines, summary = found
    first = core_lines[0].text.rstrip(":")
    out = [f"# {name}: the core, the vector loop from its entry {first} round to it, {width} lanes an iteration",
           "# (the whole function follows; --raw prints it as LLVM wrote it)"]
    out += [f"# {s}" for s in summary]
    pad = max((len(l.text.expandtabs(8)) for l in core_lines), default=40) + 2
    for line in core_lines:
        note = "; ".join([line.step] * bool(line.step) + [f"{r} = {v}" for r, v in line.constants])
        out.append(line.text.expandtabs(8).ljust(pad) + f"# {note}" if note else line.text.expandtabs(8))
    out.append("")
    out.append(f"# {name}: the whole function (prologue, the vector loop, the tail, the epilogue)")
    for raw in lines:
        refs = _REF.findall(raw)
        if refs and _is_instruction(raw):
            kind = element_kind(_operands(raw)[0])
            note = "; ".join(f"{r} = {value_text(pool[r], kind)}" for r in refs if r in pool)
            out.append(raw.expandtabs(8).ljust(pad) + f"# {note}")
        else:
            out.append(raw)
    return "\n".join(out)
