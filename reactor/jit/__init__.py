"""JIT layer: targets, LLVM optimization and code generation, object caches."""
