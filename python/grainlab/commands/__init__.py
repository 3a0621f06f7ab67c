"""Subcommands of the ``grainlab`` command line, one module each."""
