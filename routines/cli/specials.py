"""``python -m routines specials``: print the special-value tables (docs/specials.md)."""
from __future__ import annotations

from ..specials import markdown
from . import parser as command_parser

HEADER = """# Special values

What every routine returns at zeros, infinities, NaN, negative and subnormal
inputs, and at its overflow and underflow edges, in both precisions, with FMA
on and off, at every SIMD width. Results are bit-exact (the sign of zero
included; "NaN" is any NaN). Every row and every exactness rule is checked on
the compiled kernels by `tests/routines/test_specials.py`; this page is
generated from the same table (`routines/specials.py`) by
`python -m routines specials > docs/specials.md`.

NaN bits are the same on every target (avx512, avx2, sse4, aarch64): a NaN input
gives that NaN quieted, a domain error (log2 of a negative, pow(0, 0), sin(inf),
acos(2), sqrt(-1)) the default NaN 0xffc00000, which sin, cos, tan, asin, atan2
may then give a sign like any result (`docs/dsl.md`, "Targets and the same bits
everywhere"; `python -m routines crosstarget` compares every bit per target).

"""


def main(argv: list[str]) -> int:
    command_parser("specials", __doc__, ("", "> docs/specials.md")).parse_args(argv)
    print(HEADER + markdown(), end="")
    return 0
