"""Objects that travel: the pieces shared by kernels and Functions that pickle as their recipe.

A body is sent as where it lives (module and qualified name) and, when that home cannot be
imported on the other side (``__main__``, a notebook, a dask worker), as the body itself: by
value through cloudpickle where it is installed, else by its source with the plain values and
importable names it reads. ``reactor.kernels.pickling`` and ``reactor.runtime.function`` use it.
"""
from __future__ import annotations

import ast
import importlib
import inspect
import pickle
import textwrap
import types


def home(obj, body) -> tuple[str, str] | None:
    """(module, qualified name) under which ``obj`` (the ufunc or Function made from ``body``) lives."""
    module, qualname = getattr(body, "__module__", None), getattr(body, "__qualname__", "")
    if not module or "<locals>" in qualname:
        return None
    try:
        found = resolve(module, qualname)
    except Exception:  # noqa: BLE001 - not importable from here: no home
        return None
    return (module, qualname) if found is obj else None


def resolve(module: str, qualname: str):
    target = importlib.import_module(module)
    for part in qualname.split("."):
        target = getattr(target, part)
    return target


_PLAIN = (int, float, complex, str, bytes, bool, type(None))


def portable_body(body, what: str):
    """The body in a form the other side can rebuild without importing its module."""
    try:
        import cloudpickle
    except ImportError:
        cloudpickle = None
    if cloudpickle is not None:  # by value; string annotations resolved here, where their names are
        try:
            notes = inspect.get_annotations(body, eval_str=True)
        except Exception:  # noqa: BLE001 - left as they are
            notes = None
        return ("cloudpickle", cloudpickle.dumps(body), notes)
    try:
        source = textwrap.dedent(inspect.getsource(body))
    except (OSError, TypeError):
        raise pickle.PicklingError(f"{what} cannot travel: its body has no source and is not importable "
                                   f"(define it in a module, or install cloudpickle)") from None
    lines = source.splitlines()
    while lines and not lines[0].lstrip().startswith(("def ", "async def ")):
        lines.pop(0)  # the decorators: the other side builds it itself
    if body.__closure__:
        raise pickle.PicklingError(f"{what} cannot travel by source: it reads variables of an enclosing "
                                   f"function (install cloudpickle, or define it in a module)")
    names: dict[str, tuple] = {}
    for name in sorted(set(_global_names(body.__code__)) | _annotation_names("\n".join(lines))):
        if name not in body.__globals__:
            continue
        value = body.__globals__[name]
        if isinstance(value, _PLAIN) or isinstance(value, tuple) and all(isinstance(v, _PLAIN) for v in value):
            names[name] = ("value", value)
        elif isinstance(value, types.ModuleType):
            names[name] = ("module", value.__name__)
        elif getattr(value, "__module__", "__main__") != "__main__" and "<locals>" not in getattr(
                value, "__qualname__", "<locals>"):
            names[name] = ("import", value.__module__, value.__qualname__)
        else:
            raise pickle.PicklingError(f"{what} cannot travel by source: it reads {name!r}, a "
                                       f"{type(value).__name__} defined in __main__ (install cloudpickle, or "
                                       f"define them in a module)")
    return ("source", "\n".join(lines) + "\n", body.__name__, body.__code__.co_filename, names)


def _annotation_names(source: str) -> set[str]:
    """The names the ``def`` line's annotations read (evaluated where it is defined)."""
    fn = ast.parse(source).body[0]
    assert isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef))
    notes = [a.annotation for a in fn.args.args + fn.args.kwonlyargs + fn.args.posonlyargs] + [fn.returns]
    return {n.id for note in notes if note is not None for n in ast.walk(note) if isinstance(n, ast.Name)}


def _global_names(code: types.CodeType):
    yield from code.co_names
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            yield from _global_names(const)


def body_from(payload):
    if payload[0] == "cloudpickle":
        import cloudpickle
        body = cloudpickle.loads(payload[1])
        if payload[2] is not None:
            body.__annotations__ = dict(payload[2])
        return body
    _, source, name, filename, names = payload
    scope: dict = {"__name__": "__reactor_travel__"}
    for key, spec in names.items():
        if spec[0] == "value":
            scope[key] = spec[1]
        elif spec[0] == "module":
            scope[key] = importlib.import_module(spec[1])
        else:
            scope[key] = resolve(spec[1], spec[2])
    exec(compile(source, filename, "exec"), scope)  # noqa: S102 - the sender's own body
    return scope[name]


def reduce_body(obj, body, what: str):
    """(home, payload) for pickling ``obj`` made from ``body``: where it lives, and the body
    itself when that home cannot be imported elsewhere (``__main__``) or there is none."""
    where = home(obj, body)
    payload = None
    if where is None or where[0] == "__main__":  # __main__ is another program on the other side
        payload = portable_body(body, what)
    return where, payload


def find(where):
    """The object at ``where`` (module, qualified name), or None where it is not importable."""
    if where is None:
        return None
    try:
        return resolve(*where)
    except Exception:  # noqa: BLE001 - not on this side
        return None


def arrive(where, payload, accept, build, what: str):
    """The object pickled as (``where``, ``payload``) on this side: the one living at ``where`` if
    ``accept`` takes it, else ``build(body)`` from the body that came along."""
    found = find(where)
    if found is not None and accept(found):
        return found
    if payload is None:
        from .errors import ReactorError
        raise ReactorError(f"{what} {'.'.join(where or ('?',))} cannot be found on this side and came without "
                           f"its body")
    return build(body_from(payload))

