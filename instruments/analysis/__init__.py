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

TYPE_CHECKING = False  # typing.TYPE_CHECKING without loading typing; mypy and pyright read the name
if TYPE_CHECKING:  # the names above, for type checkers and editors (tests/test_typing.py holds them equal);
    # "X as X": re-exported, as a typed package's checkers read it
    from .batch import analysed as analysed
    from .pipeline import GaugeSetup as GaugeSetup
    from .pipeline import Setup as Setup
    from .pipeline import analyze_forces as analyze_forces
    from .pipeline import analyze_record as analyze_record
    from .pipeline import record_forces as record_forces
    from .pipeline import reflection_time as reflection_time
    from .pipeline import solitary_train as solitary_train
    from .plausibility import Limits as Limits
    from .pulses import MIN_BASELINE as MIN_BASELINE
    from .pulses import PeakRules as PeakRules
    from .pulses import Pulse as Pulse
    from .pulses import find_pulses as find_pulses
    from .pulses import first_peak_time as first_peak_time
    from .pulses import invert_rc as invert_rc
    from .pulses import leading as leading
    from .pulses import noise_level as noise_level
    from .pulses import refined as refined
    from .pulses import xcorr_delay as xcorr_delay
    from .report import FIGURES as FIGURES
    from .report import SPEED_FIGURES as SPEED_FIGURES
    from .report import Report as Report
