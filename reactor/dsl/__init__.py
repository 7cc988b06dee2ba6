"""DSL layer: typed values, operators, intrinsics, variables, control flow, functions."""
