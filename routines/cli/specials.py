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

"""


def main(argv: list[str]) -> int:
    command_parser("specials", __doc__, ("", "> docs/specials.md")).parse_args(argv)
    print(HEADER + markdown(), end="")
    return 0
