"""The configuration queries (programmer manuals, "Configuration Command Group": the
MDO3000's 45 ``CONFIGuration:...?`` queries, the 4 Series' ``CONFIGuration:ANALOg:BANDWidth?``):
what the emulated instrument has, for programs that size themselves by it (how many
channels to read, which options to use).

- ``ANALOg:NUMCHANnels?`` "the number of analog channels": the model's (``*IDN?``'s model
  field: an MDO3xx4 or a TDS/TPS xxx4 has 4, an MDO3xx2 or a TDS/TPS xxx2 has 2, an MSO4N
  has N), at most the four the emulated scope serves (CH1 to CH4). Kept on every model (the
  TDS2000's and the 4 Series' manuals have no such query).
- ``ANALOg:BANDWidth?`` ("the maximum licensed bandwidth") and ``ANALOg:MAXBANDWidth?``, Hz:
  the MDO3000's from its model number (MDO3012 and MDO3014 100 MHz, MDO302x 200 MHz, MDO303x
  350 MHz, MDO305x 500 MHz, MDO310x 1 GHz); the 4 Series' model number does not state it: the
  widest of its bandwidth options, 1.5 GHz (the emulated input has no limit of its own while
  CH<x>:BANDwidth is FULl). ``ANALOg:MAXSAMPLERate?``, S/s: the MDO3000's real-time rate,
  5 GS/s on the 500 MHz and 1 GHz models, 2.5 GS/s on the others (MDO3000 Series datasheet).
- ``ANALOg:RECLENS?`` "a comma-separated list of supported record lengths": the model's that
  the served scope takes (max_record_length).
- ``NUMMEAS?`` "the maximum number of periodic measurements": 8 (MEAS1 to MEAS8).
- ``ANALOg:GNDCPLG?`` 0: "this query always returns 0" on the MDO3000 (its manual).
- Every other query asks whether a feature or an option is present (a boolean: advanced
  math, the AFG, the arbitrary generator, Aux In, the DVM, the applications, the serial
  bus decoders, MagniVu, the RF channel's advanced trigger, ...) or how many waveforms of a
  kind there are (bus, digital, RF and reference waveforms): none of them is emulated, so
  0 ("If no RF channels are present, the query returns 0"); the digital and RF channels'
  rates and bandwidths are 0 as their manual text says for channels that are absent.
Booleans and counts are NR1, rates and bandwidths the model's NR3."""
from __future__ import annotations

import re

from .manual import MODELS, manual, normal
from .measurements import SLOTS

SERVED_CHANNELS = 4
MDO3000_BANDWIDTH_HZ = {"01": 100e6, "02": 200e6, "03": 350e6, "05": 500e6, "10": 1e9}
"""The MDO3000's bandwidth by the two digits after "MDO3" (MDO3024: "02", 200 MHz)."""
MSO4_BANDWIDTH_HZ = 1.5e9
NUMBERS = ("CONFIGURATION:DIGITAL:MAXSAMPLERATE", "CONFIGURATION:RF:BANDWIDTH", "CONFIGURATION:RF:MAXBANDWIDTH")
"""The queries that answer a rate or a bandwidth (NR3) of channels the scope does not have."""


def model_of(idn: str) -> str:
    """*IDN?'s model field, capitals, no spaces (``TDS 2024C`` -> ``TDS2024C``)."""
    return idn.split(",")[1].replace(" ", "").upper()


def analog_channels(model: str) -> int:
    """The analog channels of a model the personalities take, at most SERVED_CHANNELS."""
    m = re.fullmatch(r"MSO4([468])B?", model)
    last = re.sub(r"[A-Z-]+$", "", model)[-1:]  # MDO3xxN, TDS/TPS ...N[letter]: N, 4 channels or 2
    return min(int(m.group(1)) if m else 4 if last == "4" else 2, SERVED_CHANNELS)


def analog_bandwidth(model: str) -> float:
    """Hz: the MDO3000's by its model number (MDO3000_BANDWIDTH_HZ; an unlisted pair of digits
    read as hundreds of MHz), the 4 Series' widest option (MSO4_BANDWIDTH_HZ)."""
    if not model.startswith("MDO3"):
        return MSO4_BANDWIDTH_HZ
    code = model[4:6]
    return MDO3000_BANDWIDTH_HZ.get(code, int(code) * 100e6 if code.isdigit() else 1e9)


def analog_sample_rate(model: str) -> float:
    """S/s, an MDO3000's real-time sample rate (MDO3000 Series datasheet: 5 GS/s on the 500 MHz
    and 1 GHz models, 2.5 GS/s on the others)."""
    return 5e9 if analog_bandwidth(model) >= 500e6 else 2.5e9


def max_sample_rate(personality) -> float | None:
    """The highest sample rate the horizontal settings keep to on the model ``*IDN?`` names
    (horizontal.py), S/s: the MDO3000's by its bandwidth, the 4 Series' one
    (Personality.max_sample_rate); None on the TDS2000, whose one record length cannot shrink."""
    if personality.name == "mdo3000":
        return analog_sample_rate(model_of(personality.idn))
    return personality.max_sample_rate


def figures(scope) -> dict:
    """{normal header: its answer} of the queries that are not 0 (module doc)."""
    p = scope.personality
    model = model_of(p.idn)
    bandwidth = p.number(analog_bandwidth(model))
    return {
        "CONFIGURATION:ANALOG:NUMCHANNELS": str(analog_channels(model)),
        "CONFIGURATION:ANALOG:BANDWIDTH": bandwidth,
        "CONFIGURATION:ANALOG:MAXBANDWIDTH": bandwidth,
        "CONFIGURATION:ANALOG:MAXSAMPLERATE": p.number(analog_sample_rate(model)),
        "CONFIGURATION:ANALOG:RECLENS": ",".join(str(n) for n in p.record_lengths if n <= scope.max_record_length),
        "CONFIGURATION:NUMMEAS": str(SLOTS),
        **{name: p.number(0.0) for name in NUMBERS},
    }


def register(tree, scope) -> None:
    """Add the configuration queries of ``scope``'s manual (a VirtualScope), and
    ``CONFIGuration:ANALOg:NUMCHANnels?`` on every model."""
    answers = figures(scope)
    model = scope.personality.name
    headers = [c.header for c in manual(model) if c.group == "configuration"] if model in MODELS else []
    for header in dict.fromkeys(headers + ["CONFIGuration:ANALOg:NUMCHANnels"]):
        answer = answers.get(normal(header), "0")
        tree.add(header, read=lambda c, a=answer: a)
