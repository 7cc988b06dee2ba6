"""Runtime: compiling DSL functions and calling them from Python.

``entry`` emits the C entry point every compiled function gets and marshals
Python arguments for it; ``function`` holds ``reactor.Function`` (a DSL
definition that can also be compiled and called), ``Module``, ``Library`` and
``Routine`` (a compiled function).
"""
