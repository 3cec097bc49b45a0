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
