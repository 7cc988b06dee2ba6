"""LLVM: verify, optimize, emit machine code, and load it into the process.

``CompiledCode(ir_text, target, opt, exports)`` holds the machine code of one
module; ``address(name)`` gives callable addresses. Object code is cached by a
key over the IR text, the target (CPU name and features) and the options:
first in memory, then on disk (``cache.py``), so a new process that builds the
same IR skips LLVM entirely. ``pipeline`` is the one path from IR text to an
optimized module; the object code, the optimized IR and the assembly all come
from it. Compilation is serialized by one lock; building IR is not (each
thread builds its own functions).

Machine code is freed when its ``CompiledCode`` is garbage-collected.
"""
from __future__ import annotations

import functools
import hashlib
import itertools
import threading

import llvmlite
import llvmlite.binding as llvm

from ..errors import CompileError, ReactorError
from ..targets import Target
from . import cache

_lock = threading.RLock()
_library_ids = itertools.count()
CACHE_VERSION = "6"  # bump when the pipeline or the cache file format changes


@functools.cache
def _lljit():
    return llvm.create_lljit_compiler()


def toolchain() -> str:
    """What, besides the IR, decides the object code: the pipeline's version and llvmlite's."""
    return f"reactor pipeline {CACHE_VERSION}, llvmlite {llvmlite.__version__}"


def cache_key(ir_text: str, target: Target, opt: int | str) -> str:
    h = hashlib.sha256()
    for part in (CACHE_VERSION, llvmlite.__version__, target.key(), str(opt), ir_text):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()


#: reactor's pipeline (``opt=3``, the default): the passes that pay on explicitly vectorized DSL
#: code. Inline the bodies into their loops and drop the copies, promote variables to registers,
#: combine and CSE, rotate the loops. Against LLVM's O3 pipeline (``opt="llvm-o3"``) the kernels
#: run at the same speed (exp2, log2, pow and a PBR shader within 0.8%) and whole cold builds take
#: 0.72-0.76x the time (Zen 3; ``python benchmarks/bench_compile.py --pipelines`` measures it).
REACTOR_PIPELINE = ("always_inliner", "global_dead_code_eliminate", "sroa", "instruction_combine",
                    "simplify_cfg", "new_gvn", "instruction_combine", "loop_simplify", "lcssa", "loop_rotate",
                    "simplify_cfg", "aggressive_dce")


def pipeline(ir_text: str, target: Target, opt: int | str) -> llvm.ModuleRef:
    """Parse, verify and optimize IR text for ``target``: ``opt`` 3 is reactor's pipeline
    (``REACTOR_PIPELINE``), 0-2 LLVM's default pipelines, "llvm-o3" LLVM's O3."""
    with _lock:
        try:
            mod = llvm.parse_assembly(ir_text)
            mod.verify()
        except RuntimeError as exc:
            raise CompileError(f"LLVM rejected the generated IR: {exc}") from None
        pto = llvm.create_pipeline_tuning_options(speed_level=3 if opt in (3, "llvm-o3") else opt)
        pto.loop_vectorization = False  # DSL code is explicitly vectorized
        pto.slp_vectorization = False
        # Build-time Python loops unroll DSL code; LLVM's runtime unrolling of the
        # kernel loops costs ~30% of compile time and gains no measurable speed.
        pto.loop_unrolling = False
        pb = llvm.create_pass_builder(target.machine, pto)
        if opt == 3:
            mpm = llvm.create_new_module_pass_manager()
            for name in REACTOR_PIPELINE:
                getattr(mpm, f"add_{name}_pass")()
            mpm.run(mod, pb)
        else:
            pb.getModulePassManager().run(mod, pb)
        return mod


def cached_object(key: str, use_disk_cache: bool = True) -> tuple[bytes | None, str]:
    """The object code stored under ``key`` and where it came from ("memory cache", "disk cache")."""
    obj = cache.memory_get(key)
    if obj is not None:
        return obj, "memory cache"
    obj = cache.disk_get(key) if use_disk_cache else None
    return obj, "disk cache"


def listing(ir_text: str, target: Target, opt: int | str) -> tuple[str, str]:
    """The optimized IR and the assembly of ``ir_text`` (nothing is loaded or cached)."""
    mod = pipeline(ir_text, target, opt)
    with _lock:
        return str(mod), target.machine.emit_assembly(mod)


class CompiledCode:
    """Machine code for one module, loaded into the process.

    Built from ``ir_text``; or, when ``key`` (the key of IR built earlier) is
    given without it, from the object cached under that key, with
    ``ir_source()`` building the IR only if it is asked for (``ir_text``)."""

    def __init__(self, ir_text: str | None, target: Target, opt: int | str, exports: tuple[str, ...],
                 use_disk_cache: bool = True, imports: dict[str, int] | None = None, *,
                 key: str | None = None, obj: bytes | None = None, source: str = "memory cache",
                 ir_source=None, quick: bool = False):
        self.target, self.opt = target, opt
        self._ir_text, self._ir_source = ir_text, ir_source
        self.quick = quick  # emitted at LLVM's quickest code generation, never cached
        if key is None:
            if ir_text is None:
                raise ValueError("CompiledCode needs the IR text or the key of IR built before")
            key = cache_key(ir_text, target, opt) + ("/quick" if quick else "")
        self.key = key
        self.source = source  # where a given ``obj`` came from
        if obj is None and not quick:
            obj, self.source = cached_object(self.key, use_disk_cache)
        if obj is None:
            obj = self._compile(use_disk_cache and not quick)
        if not quick:
            cache.memory_put(self.key, obj)
        self.object = obj
        self._addresses: dict[str, int] = {}
        self._tracker = None
        if not target.runnable:
            return
        try:
            self._link(imports, exports)
        except RuntimeError as exc:
            if self.source.startswith("compiled"):
                raise CompileError(f"LLVM could not link the module it compiled: {exc}") from None
            # an authenticated entry that still fails to link (an llvmlite or library change):
            # heal the cache instead of failing in every later process
            cache.memory_remove(self.key)
            if "disk" in self.source:
                cache.disk_remove(self.key, ".o", f"it did not link: {str(exc).strip()[:200]}")
            self.object = self._compile(use_disk_cache)
            cache.memory_put(self.key, self.object)
            self._link(imports, exports)

    def _compile(self, use_disk_cache: bool) -> bytes:
        """Object code from the IR (built again from its source if it came from a recipe)."""
        self.source = "compiled quickly" if self.quick else "compiled"
        mod = pipeline(self.ir_text, self.target, self.opt)
        with _lock:
            obj = (self.target.quick_machine if self.quick else self.target.machine).emit_object(mod)
        if use_disk_cache:
            cache.disk_put(self.key, obj)
        return obj

    def _link(self, imports, exports) -> None:
        with _lock:
            builder = llvm.JITLibraryBuilder().add_object_img(self.object).add_current_process()
            for name, address in (imports or {}).items():
                builder.import_symbol(name, address)
            for name in exports:
                builder.export_symbol(name)
            tracker = builder.link(_lljit(), f"reactor{next(_library_ids)}")
        self._tracker = tracker
        self._addresses = {name: tracker[name] for name in exports}

    def unrunnable_reason(self) -> str:
        """Why this code cannot run on this CPU (a target whose features the CPU lacks)."""
        return (f"code built for target '{self.target.name}' cannot run on this CPU "
                f"({self.target.missing()}); inspect its assembly instead, or run it under an emulator "
                f"(reactor.Emulator)")

    def address(self, name: str) -> int:
        if not self.target.runnable:
            raise ReactorError(self.unrunnable_reason())
        return self._addresses[name]

    @property
    def ir_text(self) -> str:
        """The module's IR as built (built again on demand when the object came from a recipe)."""
        if self._ir_text is None:
            self._ir_text = self._ir_source()
        return self._ir_text

    @functools.cached_property
    def optimized_ir(self) -> str:
        return str(pipeline(self.ir_text, self.target, self.opt))

    @functools.cached_property
    def assembly(self) -> str:
        mod = pipeline(self.ir_text, self.target, self.opt)
        with _lock:
            return self.target.machine.emit_assembly(mod)


class ShowsCode:
    """The text views of something compiled, for readers of IR and assembly (``self.code``
    is its ``CompiledCode``)."""

    code: CompiledCode

    @property
    def ir(self) -> str:
        """The module's LLVM IR as built (before optimization)."""
        return self.code.ir_text

    @property
    def optimized_ir(self) -> str:
        """The module's IR after LLVM's optimization pipeline."""
        return self.code.optimized_ir

    @property
    def assembly(self) -> str:
        """The machine code, as assembly."""
        return self.code.assembly
