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
    "find": ("find_pulses", "first_peak_time", "first_peak_times", "leading", "reflection_time", "solitary_train"),
    "refine": ("refined", "xcorr_delay"),
    "plausibility": ("Limits",),
    "report": ("FIGURES", "SPEED_FIGURES", "Report"),
    "batch": ("analysed",),
}
__getattr__, __all__ = lazy_names(__name__, PUBLIC)

TYPE_CHECKING = False  # typing.TYPE_CHECKING without loading typing; mypy and pyright read the name
if TYPE_CHECKING:  # the names above, for type checkers and editors (tests/test_typing.py holds them equal);
    # "X as X": re-exported, as a typed package's checkers read it
    from .batch import analysed as analysed
    from .condition import MIN_BASELINE as MIN_BASELINE
    from .condition import invert_rc as invert_rc
    from .condition import noise_level as noise_level
    from .condition import record_forces as record_forces
    from .find import find_pulses as find_pulses
    from .find import first_peak_time as first_peak_time
    from .find import first_peak_times as first_peak_times
    from .find import leading as leading
    from .find import reflection_time as reflection_time
    from .find import solitary_train as solitary_train
    from .pipeline import analyze_forces as analyze_forces
    from .pipeline import analyze_record as analyze_record
    from .plausibility import Limits as Limits
    from .pulse import PeakRules as PeakRules
    from .pulse import Pulse as Pulse
    from .refine import refined as refined
    from .refine import xcorr_delay as xcorr_delay
    from .report import FIGURES as FIGURES
    from .report import SPEED_FIGURES as SPEED_FIGURES
    from .report import Report as Report
    from .setup import GaugeSetup as GaugeSetup
    from .setup import Setup as Setup
