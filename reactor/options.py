"""Build options and their thread-local context defaults.

``with reactor.options(fma=False, width=8): ...`` changes the defaults for
everything built in the block on this thread; an explicit keyword argument to
``Function``/``kernel`` always wins.
"""
from __future__ import annotations

import contextlib
import dataclasses
import threading

from .errors import ReactorError


@dataclasses.dataclass(frozen=True)
class BuildOptions:
    """Options that change the emitted code (all are part of cache keys).

    fma:    True emits ``llvm.fma`` for fused operations (``MulAdd``/``Fma``);
            False emits separate multiply and add and no fused instruction.
            None means the target's capability.
    width:  SIMD width for width-generic code (``SIMD.Float``); None means the
            target's natural width (16 with AVX-512, 8 with AVX2, else 4).
    opt:    LLVM optimization level 0..3.
    target: a target name from ``reactor.jit.target.TARGETS`` ("host",
            "avx512", "avx2", "sse4") or None for the context default ("host").
    cache:  use the on-disk object cache.
    """

    fma: bool | None = None
    width: int | None = None
    opt: int = 3
    target: str | None = None
    cache: bool = True

    def merged(self, **overrides) -> "BuildOptions":
        given = {k: v for k, v in overrides.items() if v is not None}
        unknown = set(given) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise ReactorError(f"unknown build option(s): {', '.join(sorted(unknown))}")
        return dataclasses.replace(self, **given)

    def resolved(self) -> "BuildOptions":
        """Fill in target-dependent defaults (target, width, fma)."""
        from .jit.target import get_target

        target = get_target(self.target or "host")
        width = self.width if self.width is not None else target.natural_width
        if width not in (1, 4, 8, 16):
            raise ReactorError(f"SIMD width must be 1, 4, 8 or 16, not {width!r}")
        if self.opt not in (0, 1, 2, 3):
            raise ReactorError(f"optimization level must be 0..3, not {self.opt!r}")
        fma = self.fma if self.fma is not None else target.has_fma
        return dataclasses.replace(self, target=target.name, width=width, fma=bool(fma))


_state = threading.local()


def current_options() -> BuildOptions:
    """The innermost ``options(...)`` context of this thread (not resolved)."""
    stack = getattr(_state, "stack", None)
    return stack[-1] if stack else BuildOptions()


@contextlib.contextmanager
def options(**overrides):
    """Context manager that sets default build options on this thread."""
    stack = getattr(_state, "stack", None)
    if stack is None:
        stack = _state.stack = []
    stack.append(current_options().merged(**overrides))
    try:
        yield stack[-1]
    finally:
        stack.pop()
