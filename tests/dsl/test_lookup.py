"""Lookup: a small constant table read per lane from registers (VPERMPS/VPERMI2PS) or memory."""
from __future__ import annotations

import numpy as np
import pytest

import reactor
from reactor import Float, Int, Lookup, kernel

TABLE = [float(i) * 1.5 - 3.0 for i in range(32)]


def _lookup(n: int, target: str):
    tab = TABLE[:n]

    def body(i: Int) -> Float:
        return Lookup(tab, i)
    return kernel(body, target=target)


@pytest.mark.parametrize("n", [2, 4, 8, 16, 32])
@pytest.mark.parametrize("target", ["host", "avx2", "sse4"])
def test_lookup_reads_the_index_modulo_the_table_size(n, target):
    i = np.arange(-300, 300, dtype=np.int32)
    i[:4] = [np.iinfo(np.int32).min, np.iinfo(np.int32).max, -1, 0]
    assert np.array_equal(_lookup(n, target)(i), np.float32(TABLE[:n])[i & (n - 1)])


def test_lookup_is_a_register_permute_where_the_target_has_one():
    text = reactor.explain(_lookup(32, "avx512")).assembly
    assert "vpermi2ps" in text or "vpermt2ps" in text
    assert "gather" not in text
    text = reactor.explain(_lookup(16, "avx2")).assembly
    assert "vperm" in text and "gather" not in text


def test_lookup_on_a_constant_index_folds():
    @kernel
    def f(x: Float) -> Float:
        return x + Lookup(TABLE, Int(5))
    assert f(np.float32([1.0]))[0] == 1.0 + TABLE[5]


@pytest.mark.parametrize("table", [[1.0], [1.0, 2.0, 3.0], [0.0] * 64])
def test_a_table_of_another_size_is_a_clear_error(table):
    def body(i: Int) -> Float:
        return Lookup(table, i)
    with pytest.raises(reactor.DSLTypeError, match="Lookup takes a table of 2, 4, 8, 16 or 32 floats"):
        kernel(body)


def test_the_index_must_be_an_int():
    def body(x: Float) -> Float:
        return Lookup(TABLE, x)
    with pytest.raises(reactor.DSLTypeError, match="Lookup's index is an Int value"):
        kernel(body)
