"""The method zoo: every exp2/log2 method of the reference write-up, measured.

``VARIANTS`` (``routines.zoo.methods``) holds each method as a named DSL
builder with its polynomials, their provenance, the reference's stated
figures and the domain they are read on; ``routines.zoo.table`` measures
them on the compiled kernels with the accuracy lab and prints both side by
side (``python -m routines zoo``). See docs/zoo.md.
"""
from .methods import BY_NAME, VARIANTS, Domain, Stated, Variant, variant

__all__ = ["BY_NAME", "VARIANTS", "Domain", "Stated", "Variant", "variant"]
