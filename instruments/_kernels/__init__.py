"""Compiled helpers of the instruments and the analysis (numba, see numerics/jit.py)."""
from numerics.jit import drop_stale_cache

drop_stale_cache(__name__)
