"""Runtime: compiling DSL functions and calling them from Python.

``entry`` emits the C entry point every compiled function gets and marshals
Python arguments for it; ``function`` holds ``reactor.Function`` (a DSL
definition that can also be compiled and called), ``Module``, ``CompiledModule`` (what a Module compiles to; ``Library`` is its old name) and
``Routine`` (a compiled function).
"""
