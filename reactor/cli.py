"""Command-line pieces shared by ``python -m reactor`` and the command lines of libraries
built on reactor (``python -m routines``, ``python -m fuzz``): loading a user's object,
printing its code, the options that choose a build, and what makes a command line behave:

* :class:`ArgumentParser`: argparse with one-line errors (``prog: error: ...``, exit 2)
  and an ``examples:`` epilog in ``--help``;
* argument types that reject bad numbers in argparse (:func:`int_type`,
  :data:`positive_int`, :data:`non_negative_int`, :data:`power_of_two`) and names outside a
  list (:func:`choice_of`);
* :func:`run`, the wrapper around a command's ``main``: a mistake of the user's
  (:class:`ReactorError`, :class:`CommandError`, a file that cannot be opened) is one line
  ``error: ...`` and exit status 2; Ctrl-C is one line ``interrupted`` and status 130; a
  closed pipe (``... | head``) ends the command quietly with status 141.
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import importlib.util
import multiprocessing
import os
import signal
import sys
import sysconfig
import threading
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

from .errors import ReactorError
from .ir.types import WIDTHS
from .targets import TARGETS

# -- argument parsing -------------------------------------------------------------------


class CommandError(Exception):
    """A mistake on the command line found after parsing: :func:`run` prints
    ``error: <message>`` and exits with status 2."""


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line (``prog: error: message``,
    exit status 2, no usage dump) and whose ``--help`` ends with ``examples``, each an
    invocation printed verbatim (the description is printed verbatim too)."""

    def __init__(self, *args: Any, examples: Sequence[str] = (), **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        if examples:
            lines = ["examples:"] + [f"  {e}" for e in examples]
            kwargs["epilog"] = "\n".join(lines) + (f"\n\n{kwargs['epilog']}" if kwargs.get("epilog") else "")
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def int_type(minimum: int | None = None, maximum: int | None = None, *,
             power_of_two: bool = False) -> Callable[[str], int]:
    """An argparse ``type=`` for integers in ``[minimum, maximum]`` (and powers of two
    with ``power_of_two``); a bad value is argparse's one-line error, e.g.
    ``argument --samples: must be a positive integer, not -5``."""
    if power_of_two:
        want = "a power of two"
    elif minimum == 1 and maximum is None:
        want = "a positive integer"
    elif minimum == 0 and maximum is None:
        want = "a non-negative integer"
    elif minimum is not None and maximum is not None:
        want = f"an integer from {minimum} to {maximum}"
    elif minimum is not None:
        want = f"an integer >= {minimum}"
    elif maximum is not None:
        want = f"an integer <= {maximum}"
    else:
        want = "an integer"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid int value: {text!r}") from None
        if ((minimum is not None and value < minimum) or (maximum is not None and value > maximum)
                or (power_of_two and (value < 1 or value & (value - 1)))):
            raise argparse.ArgumentTypeError(f"must be {want}, not {text.strip()}")
        return value

    parse.__name__ = parse.__qualname__ = want.replace(" ", "_")
    return parse


positive_int = int_type(1)
non_negative_int = int_type(0)
power_of_two = int_type(1, power_of_two=True)


def choice_of(names: Sequence[str]) -> Callable[[str], str]:
    """An argparse ``type=`` accepting one of ``names``: argparse's own ``invalid choice``
    line for anything else. Use it instead of ``choices=`` on a positional with ``nargs="*"``,
    whose empty default argparse before Python 3.12 checks against ``choices`` (and rejects)."""
    allowed = tuple(names)

    def parse(text: str) -> str:
        if text not in allowed:
            raise argparse.ArgumentTypeError(
                f"invalid choice: {text!r} (choose from {', '.join(map(repr, allowed))})")
        return text

    parse.__name__ = parse.__qualname__ = "choice"
    return parse


# -- running a command ------------------------------------------------------------------

_running = 0  # how many run() calls are active (forked children ignore Ctrl-C meanwhile)
_hooked = False


def run(main: Callable[[list[str]], int | None], argv: Sequence[str] | None = None) -> int:
    """Call ``main(argv)`` (default ``sys.argv[1:]``) and return its exit status, turning
    what a user causes into one line on stderr instead of a traceback:

    * :class:`ReactorError`, :class:`CommandError`, an ``OSError`` about a file
      (missing, unreadable): ``error: <message>``, status 2;
    * ``KeyboardInterrupt``: ``interrupted``, status 130 (processes forked meanwhile,
      such as multiprocessing workers, ignore Ctrl-C: the parent stops them);
    * ``BrokenPipeError`` on stdout (``... | head``): nothing, status 141 (Python's
      recipe: stdout is pointed at /dev/null so the exit flush cannot fail again).

    argparse's own errors (``SystemExit(2)``) pass through."""
    global _running
    _ignore_ctrl_c_in_forked_children()
    _running += 1
    try:
        status = main(sys.argv[1:] if argv is None else list(argv))
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
        return 0 if status is None else int(status)
    except KeyboardInterrupt:
        _say("interrupted")
        return 130
    except BrokenPipeError:
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):  # pragma: no cover - stdout without a descriptor
            pass
        return 141
    except (ReactorError, CommandError) as exc:
        _say(f"error: {describe(exc)}")
        return 2
    except OSError as exc:
        if exc.filename is None:
            raise
        _say(f"error: {exc.strerror or exc}: {exc.filename}")
        return 2
    finally:
        _running -= 1


def describe(exc: BaseException) -> str:
    """The one-line message of an error; a :class:`ReactorError`'s ``(at FILE:LINE)`` only
    when it names a file of the user's (not ``<frozen runpy>``, ``<string>``, the stdlib)."""
    if isinstance(exc, ReactorError) and exc.location and not _users_file(str(exc.location[0])):
        return exc.problem
    return str(exc)


def _users_file(name: str) -> bool:
    if name.startswith("<") or not os.path.isfile(name):
        return False
    stdlib = os.path.abspath(sysconfig.get_paths()["stdlib"]) + os.sep
    return not os.path.abspath(name).startswith(stdlib)


def _say(line: str) -> None:
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError):  # pragma: no cover - stderr closed too
        pass


@contextlib.contextmanager
def forked_pool(workers: int, initializer=None, initargs: tuple = ()):
    """A multiprocessing Pool of forked workers (they inherit the parent's kernels), terminated
    when the block ends. Ctrl-C is held back while the workers start and delivered inside the
    block: one in the middle of ``Pool()`` would leave a started worker that nobody ends, holding
    the command's output open."""
    ctx = multiprocessing.get_context("fork")
    held = threading.current_thread() is threading.main_thread() and hasattr(signal, "pthread_sigmask")
    old: set = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if held else set()
    try:
        pool = ctx.Pool(workers, initializer=initializer, initargs=initargs)
    except BaseException:
        if held:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        raise
    with pool:
        if held:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a Ctrl-C held back is raised here
        yield pool


def _ignore_ctrl_c_in_forked_children() -> None:
    """Ctrl-C reaches the whole process group: forked workers would each print a
    KeyboardInterrupt traceback. Children forked while a command runs ignore it; the
    parent's interrupt terminates them (multiprocessing pools do so on exit)."""
    global _hooked
    if not _hooked and hasattr(os, "register_at_fork"):
        os.register_at_fork(after_in_child=_child_after_fork)
        _hooked = True


def _child_after_fork() -> None:
    if _running:
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        except (ValueError, OSError):  # pragma: no cover - not the main thread
            pass


# -- dump -------------------------------------------------------------------------------

def load(spec: str) -> Any:
    """The object ``NAME`` of ``FILE.py:NAME`` or ``package.module:NAME``."""
    if ":" not in spec:
        raise ReactorError(f"dump target must be FILE.py:NAME or module:NAME, not {spec!r}")
    where, name = spec.rsplit(":", 1)
    if where.endswith(".py"):
        if not os.path.isfile(where):
            raise ReactorError(f"no such file: {where}")
        mod_spec = importlib.util.spec_from_file_location("reactor_dump_target", where)
        if mod_spec is None or mod_spec.loader is None:  # pragma: no cover - a .py file always has one
            raise ReactorError(f"cannot load {where}")
        module = importlib.util.module_from_spec(mod_spec)
        mod_spec.loader.exec_module(module)
    else:
        try:
            module = importlib.import_module(where)
        except ModuleNotFoundError as exc:
            if exc.name is None or not (where == exc.name or where.startswith(exc.name + ".")):
                raise  # the module exists but imports something missing: its own traceback
            raise ReactorError(f"no module named {where!r}") from None
    try:
        return getattr(module, name)
    except AttributeError:
        raise ReactorError(f"{where} has no attribute {name!r}") from None


def text(obj: Any, what: str, everything: bool = False) -> str:
    """The IR ("ir"), optimized IR ("opt") or assembly ("asm") of a Function or kernel ufunc. For a
    kernel, the body first: the traced body function (ir) or the loop it is inlined in (opt, asm);
    ``everything``: the whole module (argument unpacking, tail, strided loop, dispatcher)."""
    import numpy as np

    from .kernels.kernel import kernel_of
    from .runtime.function import Function

    item: Any  # a compiled Routine or a Kernel: both show their code
    if isinstance(obj, Function):
        item = obj.compile()
    elif isinstance(obj, np.ufunc):
        item = kernel_of(obj)
    else:
        raise ReactorError(f"{obj!r} is neither a reactor Function nor a reactor kernel")
    code = {"ir": item.ir, "opt": item.optimized_ir, "asm": item.assembly}[what]
    if everything or isinstance(obj, Function):
        return code
    name = f"{item.name}.body" if what == "ir" else f"{item.name}.loop"
    part = _function_text(code, name, what)
    if part is None:
        return code
    note = ";" if what != "asm" else "#"
    return (f"{note} {name}: {'the body as traced' if what == 'ir' else 'the loop with the body inlined'}; "
            f"--all shows the whole module\n{part}")


def _function_text(code: str, name: str, what: str) -> str | None:
    """One function of an IR module or assembly listing (None if it is not there)."""
    lines = code.splitlines()
    if what == "asm":
        start = next((i for i, l in enumerate(lines) if l.strip('"').startswith(f"{name}:") or
                      l.startswith(f'"{name}":')), None)
        if start is None:
            return None
        end = next((i for i in range(start, len(lines)) if lines[i].startswith(".Lfunc_end")), len(lines) - 1)
        return "\n".join(lines[start:end + 1])
    start = next((i for i, l in enumerate(lines) if l.startswith("define") and f'@"{name}"(' in l or
                  l.startswith("define") and f"@{name}(" in l), None)
    if start is None:
        return None
    end = next((i for i in range(start, len(lines)) if lines[i] == "}"), len(lines) - 1)
    return "\n".join(lines[start:end + 1])


def add_build_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``dump`` that choose the build (shared with ``python -m routines dump``)."""
    parser.add_argument("--what", choices=("ir", "opt", "asm"), default="asm",
                        help="IR, optimized IR or assembly (default asm)")
    parser.add_argument("--fma", choices=("on", "off", "emulate"),
                        help="fused multiply-add (default: the target's; emulate: fused in software where the "
                             "target has no FMA)")
    parser.add_argument("--width", type=int, choices=WIDTHS,
                        help="SIMD lanes (default: the target's natural width)")
    parser.add_argument("--target", dest="cpu", choices=TARGETS, help="code-generation target (default host)")
    parser.add_argument("--opt", type=int, choices=(0, 1, 2, 3), help="LLVM optimization level (default 3)")
    parser.add_argument("--all", dest="everything", action="store_true",
                        help="the whole module (a kernel's loops, tail and dispatcher), not only its body")


def build_options(args: argparse.Namespace) -> dict[str, Any]:
    fma = {None: None, "on": True, "off": False, "emulate": "emulate"}[args.fma]
    return {"fma": fma, "width": args.width,
            "target": args.cpu, "opt": args.opt}
