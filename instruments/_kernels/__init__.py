"""Compiled helpers of the instruments and the analysis (numba, see instruments/jit.py)."""
from instruments.jit import drop_stale_cache

drop_stale_cache(__name__)
