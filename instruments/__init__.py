"""The measurement side of the rig: gauges, wall sensor, oscilloscope, scope files,
archive and analysis. Works on plain arrays and records and never imports ``rig``.

Its rooms (docs/architecture.md): ``devices/`` (the forces to a scope record), ``analysis/``
(a record to a Report), ``formats/`` (scope files), ``archive/`` (the HDF5 archive), the lab
front (``scpi/``, ``transports/``, ``virtual_scope/``) and the records, rails, errors and
files beneath them. The two wings' public names are named here too, each loaded on first
use (``from instruments import Oscilloscope, analyze_record``)."""
from .analysis import PUBLIC as ANALYSIS
from .devices import PUBLIC as DEVICES
from .facade import lazy_names

__getattr__, __all__ = lazy_names(__name__, {**{f"analysis.{m}": names for m, names in ANALYSIS.items()},
                                             **{f"devices.{m}": names for m, names in DEVICES.items()}})

TYPE_CHECKING = False  # typing.TYPE_CHECKING without loading typing; mypy and pyright read the name
if TYPE_CHECKING:  # the names above, for type checkers and editors (tests/test_typing.py holds them equal);
    # "X as X": re-exported, as a typed package's checkers read it
    from .analysis.batch import analysed as analysed
    from .analysis.condition import MIN_BASELINE as MIN_BASELINE
    from .analysis.condition import invert_rc as invert_rc
    from .analysis.condition import noise_level as noise_level
    from .analysis.condition import record_forces as record_forces
    from .analysis.find import find_pulses as find_pulses
    from .analysis.find import first_peak_time as first_peak_time
    from .analysis.find import first_peak_times as first_peak_times
    from .analysis.find import leading as leading
    from .analysis.find import reflection_time as reflection_time
    from .analysis.find import solitary_train as solitary_train
    from .analysis.pipeline import analyze_forces as analyze_forces
    from .analysis.pipeline import analyze_record as analyze_record
    from .analysis.plausibility import Limits as Limits
    from .analysis.pulse import PeakRules as PeakRules
    from .analysis.pulse import Pulse as Pulse
    from .analysis.refine import refined as refined
    from .analysis.refine import xcorr_delay as xcorr_delay
    from .analysis.report import FIGURES as FIGURES
    from .analysis.report import SPEED_FIGURES as SPEED_FIGURES
    from .analysis.report import Report as Report
    from .analysis.setup import GaugeSetup as GaugeSetup
    from .analysis.setup import Setup as Setup
    from .devices.batch import NO_TRIGGER as NO_TRIGGER
    from .devices.batch import OK as OK
    from .devices.batch import PAST_INPUT as PAST_INPUT
    from .devices.batch import Records as Records
    from .devices.batch import Wiring as Wiring
    from .devices.batch import acquire as acquire
    from .devices.frontend import highpass_coefficients as highpass_coefficients
    from .devices.frontend import lowpass as lowpass
    from .devices.frontend import lowpass_coefficients as lowpass_coefficients
    from .devices.frontend import rc_highpass as rc_highpass
    from .devices.gauges import GaugeDraw as GaugeDraw
    from .devices.gauges import GaugeSettings as GaugeSettings
    from .devices.gauges import PiezoGauge as PiezoGauge
    from .devices.oscilloscope import CHANNELS as CHANNELS
    from .devices.oscilloscope import ChannelSettings as ChannelSettings
    from .devices.oscilloscope import FrontPanel as FrontPanel
    from .devices.oscilloscope import Oscilloscope as Oscilloscope
    from .devices.oscilloscope import Timebase as Timebase
    from .devices.oscilloscope import Trigger as Trigger
