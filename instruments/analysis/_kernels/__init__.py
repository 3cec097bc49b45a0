"""The analysis' compiled loops (numba, see numerics/jit.py), beneath the pipeline: the
peak rules of scipy.signal.find_peaks (peaks.py, prominence.py), the parabola through a
pulse's top (parabola.py), level crossings (crossings.py), numpy's selections as loops
(select.py), a channel's baseline, noise and force (baseline.py), a record's pulses
(pulses.py) and their delay by cross-correlation (correlation.py), and a batch's records
through them (batch_analysis.py). The shared inverse filter they inline and the
acquisition status a batch reads join the cache's digest."""
from numerics.jit import drop_stale_cache

drop_stale_cache(__name__, constants=("instruments._kernels.filters", "instruments.devices._kernels.acquisition"))
