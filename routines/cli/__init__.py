"""Subcommands of ``python -m routines``, and what they share.

Every command is a module with ``main(argv) -> int`` (tests call it directly);
``python -m routines`` runs it through :func:`run`, so that a user's mistake is
one line ``error: ...`` (exit status 2), Ctrl-C is one line ``interrupted``
(status 130) and ``... | head`` ends quietly (status 141), never a traceback.

* :func:`parser` -- an :class:`ArgumentParser` named ``python -m routines NAME``
  with one-line argparse errors and ``examples:`` in ``--help``;
* argument types: :data:`positive_int`, :data:`non_negative_int`,
  :data:`power_of_two`, :func:`int_type` (any range), :func:`choice_of` (a name of a list);
* :func:`add_quiet` -- the ``--quiet`` option of long commands; progress bars
  are drawn only when stderr is a terminal (tqdm's ``disable=None``) and never
  with ``--quiet``;
* :class:`CommandError` -- raise it for a mistake found after parsing.

The generic pieces live in :mod:`reactor.cli` (``python -m reactor`` and
``python -m fuzz`` use them too); this module re-exports them.
"""
from __future__ import annotations

from reactor.cli import (ArgumentParser, CommandError, choice_of, describe, int_type, non_negative_int,
                         positive_int, power_of_two, run)

__all__ = ["ArgumentParser", "CommandError", "add_quiet", "choice_of", "describe", "int_type", "non_negative_int",
           "parser", "positive_int", "power_of_two", "run"]


def parser(name: str, description: str | None, examples) -> ArgumentParser:
    """The parser of ``python -m routines NAME``; ``examples`` are argument strings
    (``"exp2 --fma off"``), shown in ``--help`` as ``python -m routines NAME exp2 --fma off``."""
    prog = f"python -m routines {name}"
    return ArgumentParser(prog=prog, description=description,
                          examples=[f"{prog} {e}".rstrip() for e in examples])


def add_quiet(p: ArgumentParser, what: str = "no progress bars") -> None:
    """``--quiet``; progress bars are shown only on a terminal, and never with it."""
    p.add_argument("-q", "--quiet", action="store_true", help=what)
