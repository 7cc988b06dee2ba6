"""Variant search: candidates for exp2/log2 (form, degree, weight, evaluation,
conversion, FMA), each built as a routine, measured on its compiled code and
costed with the dataflow model; the Pareto set of cost vs Vulkan margin.
See docs/search.md."""
from .candidates import Candidate, grid, production
from .run import Point, measure, pareto, search

__all__ = ["Candidate", "Point", "grid", "measure", "pareto", "production", "search"]
