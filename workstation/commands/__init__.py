"""Subcommands of the command line, one module each (the CLI itself stays thin)."""
