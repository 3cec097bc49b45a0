"""Compiled helpers of the analysis (numba)."""
