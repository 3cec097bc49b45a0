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
