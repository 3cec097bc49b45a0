"""The devices: what turns the chain's forces into a scope record. ``gauges.py`` (the
piezo gauges and the wall sensor), ``frontend.py`` (their analog conditioning: the RC
high-pass, the scope's bandwidth), ``oscilloscope.py`` (the scope: channels, timebase,
trigger, the 8-bit converter), ``batch.py`` (the instruments of many shots at once, the
same bits as one shot alone), ``_kernels/`` (their compiled loops, numba). They never
import the analysis. The names below load on first use.
"""
from ..facade import lazy_names

PUBLIC = {  # {module: its public names}
    "gauges": ("GaugeDraw", "GaugeSettings", "PiezoGauge"),
    "frontend": ("highpass_coefficients", "lowpass", "lowpass_coefficients", "rc_highpass"),
    "oscilloscope": ("CHANNELS", "ChannelSettings", "FrontPanel", "Oscilloscope", "Timebase", "Trigger"),
    "batch": ("NO_TRIGGER", "OK", "PAST_INPUT", "Records", "Wiring", "acquire"),
}
__getattr__, __all__ = lazy_names(__name__, PUBLIC)

TYPE_CHECKING = False  # typing.TYPE_CHECKING without loading typing; mypy and pyright read the name
if TYPE_CHECKING:  # the names above, for type checkers and editors (tests/test_typing.py holds them equal);
    # "X as X": re-exported, as a typed package's checkers read it
    from .batch import NO_TRIGGER as NO_TRIGGER
    from .batch import OK as OK
    from .batch import PAST_INPUT as PAST_INPUT
    from .batch import Records as Records
    from .batch import Wiring as Wiring
    from .batch import acquire as acquire
    from .frontend import highpass_coefficients as highpass_coefficients
    from .frontend import lowpass as lowpass
    from .frontend import lowpass_coefficients as lowpass_coefficients
    from .frontend import rc_highpass as rc_highpass
    from .gauges import GaugeDraw as GaugeDraw
    from .gauges import GaugeSettings as GaugeSettings
    from .gauges import PiezoGauge as PiezoGauge
    from .oscilloscope import CHANNELS as CHANNELS
    from .oscilloscope import ChannelSettings as ChannelSettings
    from .oscilloscope import FrontPanel as FrontPanel
    from .oscilloscope import Oscilloscope as Oscilloscope
    from .oscilloscope import Timebase as Timebase
    from .oscilloscope import Trigger as Trigger
