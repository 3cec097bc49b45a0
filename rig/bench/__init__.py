"""Benchmarks (`rig bench WHAT`): each module has run() -> dict and table(result) -> str."""
