"""Every routine variant conforms to its Vulkan tolerance on >= 2^20 sampled inputs
(plus every hard region of routines.lab.sample_inputs), measured on the compiled
kernel against the mpmath-audited float64 reference; every width computes the
same bits."""
import itertools

import numpy as np
import pytest

import routines
from routines.lab import evaluate, sample_inputs

VARIANTS = list(itertools.product(routines.NAMES, ("full", "relaxed"), (True, False)))


@pytest.mark.parametrize("name,precision,fma", VARIANTS)
def test_variant_conforms_on_a_large_sample(name, precision, fma):
    operands = sample_inputs(name, 2 ** 20, seed=11)
    assert operands[0].size >= 2 ** 20
    result = evaluate(routines.jit(name, precision, fma), name, precision, *operands)
    assert sum(result.special_mismatches.values()) == 0, result.table()
    assert result.nonconforming == 0, result.table()
    assert result.max_margin < 1.0


@pytest.mark.parametrize("name", routines.NAMES)
def test_every_width_computes_the_same_bits(name):
    operands = [b.view(np.float32) for b in sample_inputs(name, 2 ** 14, seed=5)]
    for precision, fma in itertools.product(("full", "relaxed"), (True, False)):
        results = [routines.jit(name, precision, fma, w)(*operands) for w in (1, 4, 8, 16)]
        for r in results[1:]:
            assert np.array_equal(r.view(np.uint32), results[0].view(np.uint32)), (precision, fma)


@pytest.mark.parametrize("name", ["exp2", "log2", "pow"])
def test_fma_changes_results_only_within_tolerance_and_really_changes_code(name):
    from reactor import kernel_of
    asm_on = kernel_of(routines.jit(name, "full", True)).assembly
    asm_off = kernel_of(routines.jit(name, "full", False)).assembly
    assert "vfmadd" in asm_on and "vfmadd" not in asm_off and "vfnmadd" not in asm_off
