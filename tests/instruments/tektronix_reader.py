"""Tektronix's own reader (tm_data_types) run in its own interpreter: it pins numpy < 2, so
it cannot share the rig's. RIG_TMDT_PYTHON names that interpreter; without it the tests
that need it are skipped, saying how to make one."""
import json
import os
import subprocess

import numpy as np
import pytest

_SCRIPT = """
import json, sys
import numpy as np
import tm_data_types as tm
out = []
for path in sys.argv[1:]:
    w = tm.read_file(path)
    out.append({"source": w.source_name, "zero_index": float(w.trigger_index),
                "spacing": float(w.y_axis_spacing) if hasattr(w, "y_axis_spacing") else None,
                "codes": np.asarray(w.y_axis_values, dtype=float).tolist(),
                "t": np.asarray(w.normalized_horizontal_values, dtype=float).tolist(),
                "v": np.asarray(w.normalized_vertical_values, dtype=float).tolist()})
print(json.dumps(out))
"""


_WRITE_IQ = """
import sys
import numpy as np
import tm_data_types as tm
w = tm.IQWaveform()
w.interleaved_iq_axis_values = np.tile(np.array([1, 2, 3, 4], dtype=np.int16), 100)
w.iq_axis_spacing, w.x_axis_spacing = 1e-3, 1e-6
w.meta_info = tm.IQWaveformMetaInfo(iq_center_frequency=1e9, iq_fft_length=1024, iq_resolution_bandwidth=1e3,
                                    iq_span=1e6, iq_window_type="Blackharris", iq_sample_rate=1.25e6)
tm.write_file(sys.argv[1], w)
"""


_WRITE_DIGITAL = """
import sys
import numpy as np
import tm_data_types as tm
w = tm.DigitalWaveform()
w.y_axis_byte_values = (np.arange(400) % 7).astype(np.uint8)
w.x_axis_spacing, w.trigger_index = 1e-6, 40.0
for path in sys.argv[1:]:
    tm.write_file(path, w)
"""


def _run(script: str, *args) -> str:
    python = os.environ.get("RIG_TMDT_PYTHON")
    if not python or not os.path.exists(python):
        if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
            pytest.fail("RIG_TMDT_PYTHON names no interpreter (.ci/run makes one): CI must compare with tm_data_types")
        pytest.skip("set RIG_TMDT_PYTHON to an interpreter with tm_data_types (it pins numpy < 2): "
                    "python3 -m venv tmdt && tmdt/bin/pip install tm_data_types")
    run = subprocess.run([python, "-c", script, *map(str, args)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    return run.stdout


def read_with_tm_data_types(paths) -> list:
    """For each file, what tm_data_types reads: {source, zero_index, spacing, codes, t, v}
    (numpy arrays for the last four but spacing)."""
    out = json.loads(_run(_SCRIPT, *paths))
    return [{**w, **{k: np.asarray(w[k]) for k in ("codes", "t", "v")}} for w in out]


def write_digital(*paths) -> None:
    """A digital record (eight bits a sample) as Tektronix's own writer makes it, in each
    path's format (.csv: Waveform Type DIGITAL, CH1_D0..CH1_D7 columns; .wfm)."""
    _run(_WRITE_DIGITAL, *paths)


def write_iq_wfm(path) -> None:
    """An IQ .wfm as Tektronix's own writer makes it (interleaved I/Q, tekmeta IQ_ keys)."""
    _run(_WRITE_IQ, path)
