"""The devices' compiled loops (numba, see numerics/jit.py): a gauge's signal chain and the
scope's acquisition (acquisition.py), its converter (quantiser.py) and its sampling of the
simulated force (resample.py). The shared filters and generator they inline join the
cache's digest."""
from numerics.jit import drop_stale_cache

drop_stale_cache(__name__, constants=("instruments._kernels.filters", "instruments._kernels.pcg64"))
