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


def read_with_tm_data_types(paths) -> list:
    """For each file, what tm_data_types reads: {source, zero_index, spacing, codes, t, v}
    (numpy arrays for the last four but spacing)."""
    python = os.environ.get("RIG_TMDT_PYTHON")
    if not python or not os.path.exists(python):
        pytest.skip("set RIG_TMDT_PYTHON to an interpreter with tm_data_types (it pins numpy < 2): "
                    "python3 -m venv tmdt && tmdt/bin/pip install tm_data_types")
    run = subprocess.run([python, "-c", _SCRIPT, *map(str, paths)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    return [{**w, **{k: np.asarray(w[k]) for k in ("codes", "t", "v")}} for w in json.loads(run.stdout)]
