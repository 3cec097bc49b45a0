"""The emulated Tektronix scope behind the SCPI engine: a ``MessageInstrument``
(``instrument.VirtualScope``) built from the scene's ``Oscilloscope`` and an injected shot
source (instruments never import the rig). ``personalities.py`` the models it can claim,
``settings.py`` its settings as scene keys, ``acquisition.py`` shots and seeds,
``transfer.py`` CURVe? and the preamble, the command tables ``common.py``, ``commands.py``,
``waveform_commands.py`` and ``rig_commands.py`` (the RIG: subsystem)."""

from .acquisition import Shot, ShotSource
from .instrument import VirtualScope

__all__ = ["Shot", "ShotSource", "VirtualScope"]
