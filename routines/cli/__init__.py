"""Subcommands of ``python -m routines``."""
