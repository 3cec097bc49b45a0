"""The implementations of the `rig` subcommands (rig/cli.py parses the arguments)."""
