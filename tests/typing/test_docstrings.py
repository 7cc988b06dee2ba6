"""Every public name of reactor, routines and routines.glsl says what it is: a callable, class or
module by its docstring, a constant by a line of its package's docstring; each GLSL built-in gives
GLSL's signatures first (``help(routines.glsl.mix)``)."""
from __future__ import annotations

import inspect
import re

import pytest

import reactor
import routines
import routines.glsl as glsl

PACKAGES = (reactor, routines, glsl)
#: Constants not documented yet (an expected failure each, strict: it says when one is done).
KNOWN_GAPS: set[str] = set()


def _public():
    for package in PACKAGES:
        for name in package.__all__:
            yield package, name, getattr(package, name)


def _is_data(obj) -> bool:
    """A constant (a tuple, dict, number ...), which has no docstring of its own."""
    return type(obj).__module__ == "builtins" and not callable(obj) and not inspect.ismodule(obj)


def _doc(obj) -> str:
    """The object's own docstring, or its class's when the class is the project's (``reactor.SIMD``)."""
    own = obj.__dict__.get("__doc__") if isinstance(obj, type) else getattr(obj, "__doc__", None)
    if own is None and not isinstance(obj, type) and type(obj).__module__.split(".")[0] in ("reactor", "routines"):
        own = type(obj).__doc__
    return inspect.cleandoc(own or "")


def _trivial(text: str) -> bool:
    return len(text) < 12 or len(text.split()) < 3


PUBLIC = [pytest.param(package, name, obj, id=f"{package.__name__}.{name}",
                       marks=[pytest.mark.xfail(strict=True, reason="not documented yet")]
                       if f"{package.__name__}.{name}" in KNOWN_GAPS else [])
          for package, name, obj in _public()]


def test_the_public_names_are_all_there():
    assert len(PUBLIC) > 250
    assert {"Float", "Float4", "vec3", "mat3", "Select", "kernel", "WIDTHS"} <= set(reactor.__all__)


@pytest.mark.parametrize("package, name, obj", PUBLIC)
def test_every_public_name_is_documented(package, name, obj):
    if _is_data(obj):
        assert re.search(rf"``{name}``: \w+", package.__doc__ or ""), \
            f"{package.__name__}.{name} is a constant: its package's docstring needs a line '``{name}``: ...'"
    else:
        text = _doc(obj)
        assert not _trivial(text), f"{package.__name__}.{name} has no docstring worth the name: {text!r}"


@pytest.mark.parametrize("name", [n for n in reactor.__all__ if isinstance(getattr(reactor, n), type)
                                  and issubclass(getattr(reactor, n), (reactor.Value, reactor.Vec, reactor.Mat))
                                  and n not in ("Value", "Vec", "Mat")])
def test_each_value_vector_and_matrix_class_says_what_it_holds(name):
    text = _doc(getattr(reactor, name))
    assert text.startswith(f"{name}: "), text
    assert re.search(r"float|integer|mask|Float|Int|UInt|Bool|UByte|UShort|Half|Double", text)


def test_glsl_mix_gives_glsls_signatures_and_meaning():
    text = inspect.getdoc(glsl.mix) or ""
    assert text.startswith("GLSL: genType mix(genType x, genType y, genType a)")
    for form in ("genType mix(genType x, genType y, float a)", "genType mix(genType x, genType y, genBType a)"):
        assert form in text
    assert "x * (1 - a) + y * a" in text and "no precision= option" in text
    assert "GLSL: genType mix" in pydoc_text(glsl.mix)


def pydoc_text(obj) -> str:
    import pydoc
    return pydoc.render_doc(obj, renderer=pydoc.plaintext)


@pytest.mark.parametrize("name", glsl.__all__)
def test_each_glsl_builtin_gives_its_glsl_signature_first(name):
    text = inspect.getdoc(getattr(glsl, name)) or ""
    spelled = {"not_": "not", "atan2": "atan"}.get(name, name)
    first = text.splitlines()[0] if text else ""
    assert re.match(rf"GLSL: \w+ {spelled}\(\w+ \w+", first), first
    body = text.split("\n\n")
    assert len(body) >= 3 and not _trivial(body[1]), text  # signatures, meaning, precision


@pytest.mark.parametrize("name, note", [("exp2", "precision= on the call"), ("pow", "fma=None follows"),
                                        ("normalize", "precision="), ("fma", "FMA option is on"),
                                        ("floor", "no precision= option"), ("dot", "no precision= option")])
def test_glsl_docstrings_say_how_precision_and_fma_apply(name, note):
    assert note in (inspect.getdoc(getattr(glsl, name)) or "")
