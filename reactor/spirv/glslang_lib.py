"""glslang in this process, through its C interface (``glslang_c_interface.h``) with ctypes: the
``glslangValidator`` command's work without a process per shader. glslang builds its built-in
symbol tables once per process (~90 ms), so every shader after the first compiles in ~2 ms
instead of ~90. Used for the cmeel wheel's glslang 13 only, whose structures are declared below
as its headers declare them (other builds: the command, ``glsl.py``)."""
from __future__ import annotations

import ctypes as C
import functools
import os
import threading

# glslang_c_shader_types.h (glslang 13)
SOURCE_GLSL, CLIENT_VULKAN, TARGET_SPV = 1, 1, 1
VULKAN_1_0, SPV_1_0, NO_PROFILE = 1 << 22, 1 << 16, 1 << 0
MSG_SPV_RULES, MSG_VULKAN_RULES, MSG_DEBUG_INFO = 1 << 3, 1 << 4, 1 << 10
AUTO_MAP_BINDINGS, AUTO_MAP_LOCATIONS, VULKAN_RULES_RELAXED = 1 << 0, 1 << 1, 1 << 2
STAGES = {"vertex": 0, "fragment": 4, "compute": 5}
MESSAGES = MSG_SPV_RULES | MSG_VULKAN_RULES | MSG_DEBUG_INFO
#: what ``glsl.FLAGS`` asks of the command: relaxed Vulkan rules, locations and bindings mapped
OPTIONS = AUTO_MAP_BINDINGS | AUTO_MAP_LOCATIONS | VULKAN_RULES_RELAXED


class _Callbacks(C.Structure):  # glsl_include_callbacks_t
    _fields_ = [("include_system", C.c_void_p), ("include_local", C.c_void_p), ("free_include_result", C.c_void_p)]


class _Input(C.Structure):  # glslang_input_t
    _fields_ = [("language", C.c_int), ("stage", C.c_int), ("client", C.c_int), ("client_version", C.c_int),
                ("target_language", C.c_int), ("target_language_version", C.c_int), ("code", C.c_char_p),
                ("default_version", C.c_int), ("default_profile", C.c_int),
                ("force_default_version_and_profile", C.c_int), ("forward_compatible", C.c_int),
                ("messages", C.c_int), ("resource", C.c_void_p), ("callbacks", _Callbacks),
                ("callbacks_ctx", C.c_void_p)]


class _SpvOptions(C.Structure):  # glslang_spv_options_t
    _fields_ = [(name, C.c_bool) for name in (
        "generate_debug_info", "strip_debug_info", "disable_optimizer", "optimize_size", "disassemble", "validate",
        "emit_nonsemantic_shader_debug_info", "emit_nonsemantic_shader_debug_source", "compile_only")]


_SIGNATURES = {  # name: (result, arguments)
    "glslang_initialize_process": (C.c_int, []),
    "glslang_shader_create": (C.c_void_p, [C.POINTER(_Input)]),
    "glslang_shader_set_options": (None, [C.c_void_p, C.c_int]),
    "glslang_shader_preprocess": (C.c_int, [C.c_void_p, C.POINTER(_Input)]),
    "glslang_shader_parse": (C.c_int, [C.c_void_p, C.POINTER(_Input)]),
    "glslang_shader_get_info_log": (C.c_char_p, [C.c_void_p]),
    "glslang_shader_delete": (None, [C.c_void_p]),
    "glslang_program_create": (C.c_void_p, []),
    "glslang_program_add_shader": (None, [C.c_void_p, C.c_void_p]),
    "glslang_program_link": (C.c_int, [C.c_void_p, C.c_int]),
    "glslang_program_map_io": (C.c_int, [C.c_void_p]),
    "glslang_program_set_source_file": (None, [C.c_void_p, C.c_int, C.c_char_p]),
    "glslang_program_get_info_log": (C.c_char_p, [C.c_void_p]),
    "glslang_program_delete": (None, [C.c_void_p]),
}
_SPIRV_SIGNATURES = {
    "glslang_program_SPIRV_generate_with_options": (None, [C.c_void_p, C.c_int, C.POINTER(_SpvOptions)]),
    "glslang_program_SPIRV_get_size": (C.c_size_t, [C.c_void_p]),
    "glslang_program_SPIRV_get_ptr": (C.POINTER(C.c_uint32), [C.c_void_p]),
}


class CompileError(Exception):
    """glslang refused the shader: its log (``ERROR: name:line: ...`` lines)."""


class Glslang:
    """The libraries, loaded; :meth:`compile` is serialized (one shader at a time)."""

    def __init__(self, lib_dir: str) -> None:
        self.core = C.CDLL(os.path.join(lib_dir, "libglslang.so.13"), mode=C.RTLD_GLOBAL)
        self.spirv = C.CDLL(os.path.join(lib_dir, "libSPIRV.so.13"), mode=C.RTLD_GLOBAL)
        limits = C.CDLL(os.path.join(lib_dir, "libglslang-default-resource-limits.so.13"))
        for lib, table in ((self.core, _SIGNATURES), (self.spirv, _SPIRV_SIGNATURES)):
            for name, (result, args) in table.items():
                fn = getattr(lib, name)
                fn.restype, fn.argtypes = result, args
        limits.glslang_default_resource.restype = C.c_void_p
        self.resource = limits.glslang_default_resource()
        self.lock = threading.Lock()
        self.core.glslang_initialize_process()

    def compile(self, source: str, stage: str, name: str) -> bytes:
        """SPIR-V for Vulkan 1.0 of ``source`` with OpLine naming ``name`` (as ``glslangValidator
        -V -g -R --aml --amb``); :class:`CompileError` with glslang's log where it fails."""
        code = source.encode("utf-8")
        shader_input = _Input(SOURCE_GLSL, STAGES[stage], CLIENT_VULKAN, VULKAN_1_0, TARGET_SPV, SPV_1_0, code,
                              100, NO_PROFILE, 0, 0, MESSAGES, self.resource, _Callbacks(), None)
        g = self.core
        with self.lock:
            shader = g.glslang_shader_create(C.byref(shader_input))
            program = None
            try:
                g.glslang_shader_set_options(shader, OPTIONS)
                if not (g.glslang_shader_preprocess(shader, C.byref(shader_input))
                        and g.glslang_shader_parse(shader, C.byref(shader_input))):
                    raise CompileError(_log(g.glslang_shader_get_info_log(shader), name))
                program = g.glslang_program_create()
                g.glslang_program_add_shader(program, shader)
                if not g.glslang_program_link(program, MESSAGES) or not g.glslang_program_map_io(program):
                    raise CompileError(_log(g.glslang_program_get_info_log(program), name))
                g.glslang_program_set_source_file(program, STAGES[stage], name.encode("utf-8"))
                options = _SpvOptions(generate_debug_info=True)
                self.spirv.glslang_program_SPIRV_generate_with_options(program, STAGES[stage], C.byref(options))
                size = self.spirv.glslang_program_SPIRV_get_size(program)
                return C.string_at(self.spirv.glslang_program_SPIRV_get_ptr(program), size * 4)
            finally:
                if program is not None:
                    g.glslang_program_delete(program)
                g.glslang_shader_delete(shader)


def _log(raw: bytes | None, name: str) -> str:
    """glslang's log with the source's name where it says ``0:`` (the string it compiled)."""
    text = (raw or b"").decode("utf-8", "replace")
    return "\n".join(line.replace(": 0:", f": {name}:", 1) for line in text.splitlines())


@functools.cache
def library(lib_dir: str) -> Glslang | None:
    """glslang 13 from ``lib_dir`` (the cmeel wheel's ``lib``), or None where it is another
    version or will not load (the command is used then)."""
    if not os.path.exists(os.path.join(lib_dir, "libglslang.so.13")) or \
            not os.path.exists(os.path.join(lib_dir, "libSPIRV.so.13")):
        return None
    try:
        return Glslang(lib_dir)
    except (OSError, AttributeError):
        return None
