"""The analysis: scope records, real or virtual, to a speed and an amplitude, as Daraio et
al. (2006) measured them. Read it top-down:

- ``pipeline.py``: a record through the stages below, to a ``Report``;
- ``pulses.py``: condition (baseline, noise, the RC high-pass undone, volts to force), find
  (the peak rules of scipy.signal.find_peaks) and refine (a parabola through each top, the
  delay by cross-correlation);
- ``plausibility.py`` and ``distortion.py``: judge (a speed a chain can have; a clipped
  top, a bandwidth too narrow, a record that ends in the pulse);
- ``report.py``: the figures, and for each one missing, why;
- ``batch.py``: the same for many shots at once;
- ``_kernels/``: the compiled loops beneath them (numba).

It reads records (instruments.records, instruments.rails) and, for a batch, the devices'
records (instruments.devices.batch); the devices never import it. The names below load
on first use, so ``instruments.analysis.report`` stays light.
"""
from ..facade import lazy_names

PUBLIC = {  # {module: its public names}
    "pulses": ("MIN_BASELINE", "PeakRules", "Pulse", "find_pulses", "first_peak_time", "invert_rc", "leading",
               "noise_level", "refined", "xcorr_delay"),
    "pipeline": ("GaugeSetup", "Setup", "analyze_forces", "analyze_record", "record_forces", "reflection_time",
                 "solitary_train"),
    "plausibility": ("Limits",),
    "report": ("FIGURES", "SPEED_FIGURES", "Report"),
    "batch": ("analysed",),
}
__getattr__, __all__ = lazy_names(__name__, PUBLIC)
