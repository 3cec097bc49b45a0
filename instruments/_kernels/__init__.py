"""Compiled loops both wings of the instruments share (numba, see numerics/jit.py): the
one-pole filter and its inverse (filters.py: the gauges' and the scope's front end, undone
by the analysis) and numpy's default generator (pcg64.py: the devices' and a study's draws)."""
from numerics.jit import drop_stale_cache

drop_stale_cache(__name__)
