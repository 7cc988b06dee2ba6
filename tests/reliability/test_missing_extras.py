"""An optional dependency that is missing is named with the extra that installs it, not a bare
ModuleNotFoundError."""
import sys

import numpy as np
import pytest

import reactor
from reactor import MissingDependencyError, require


@pytest.fixture
def without(monkeypatch):
    """Make the named top-level modules unimportable for the test."""
    def hide(*names):
        for name in list(sys.modules):
            if name.split(".")[0] in names:
                monkeypatch.delitem(sys.modules, name)
        for name in names:
            monkeypatch.setitem(sys.modules, name, None)  # import raises ModuleNotFoundError
    return hide


def test_map_blocks_without_dask_names_the_extra(without):
    without("dask")
    with pytest.raises(MissingDependencyError, match=r"reactor.map_blocks needs dask, .* pip install "
                                                     r"'reactor-simd\[distributed\]'"):
        reactor.map_blocks(np.add, np.ones(3), np.ones(3))


def test_mpmath_for_the_lab_names_the_lab_extra(without):
    without("mpmath")
    from routines import doubled
    with pytest.raises(MissingDependencyError, match=r"needs mpmath.*reactor-simd\[lab\]"):
        doubled.constant(1)


def test_it_is_an_import_error_and_a_present_module_is_returned():
    assert issubclass(MissingDependencyError, ImportError)
    assert require("numpy", "dev", "this test") is np
