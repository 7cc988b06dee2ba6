"""Kernels: compiled loops exposed as NumPy ufuncs."""
