"""The analysis: scope records, real or virtual, to a speed and an amplitude, as Daraio et
al. (2006) measured them. Read it top-down:

- ``pipeline.py``: a record through the stages below, in order, to a ``Report``;
- ``condition.py``: baseline, noise, the RC high-pass undone, volts to force;
- ``find.py``: the peak rules of scipy.signal.find_peaks, the leading pulse, the train;
- ``refine.py``: a parabola through each top, the widths, the delay by cross-correlation;
- ``judge.py``: each figure given or refused with its reason, by the rules of
  ``plausibility.py`` (a speed a chain can have) and ``distortion.py`` (a clipped top, a
  bandwidth too narrow, a record that ends in the pulse);
- ``report.py``: the figures, and for each one missing, why;
- ``batch.py``: the same for many shots at once;
- ``pulse.py`` and ``setup.py``: what every stage reads (a Pulse, the PeakRules; the Setup);
- ``_kernels/``: the compiled loops beneath them (numba).

It reads records (instruments.records, instruments.rails) and, for a batch, the devices'
records (instruments.devices.batch); the devices never import it. The names below load
on first use, so ``instruments.analysis.report`` stays light.
"""
from ..facade import lazy_names

PUBLIC = {  # {module: its public names}
    "pipeline": ("analyze_forces", "analyze_record"),
    "setup": ("GaugeSetup", "Setup"),
    "pulse": ("PeakRules", "Pulse"),
    "condition": ("MIN_BASELINE", "invert_rc", "noise_level", "record_forces"),
    "find": ("find_pulses", "first_peak_time", "leading", "reflection_time", "solitary_train"),
    "refine": ("refined", "xcorr_delay"),
    "plausibility": ("Limits",),
    "report": ("FIGURES", "SPEED_FIGURES", "Report"),
    "batch": ("analysed",),
}
__getattr__, __all__ = lazy_names(__name__, PUBLIC)
