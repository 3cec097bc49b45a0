#!/usr/bin/env bash
# The scaling table of rig mc on a many-core machine, in one go (under 8 minutes on 16 cores):
# install the rig (where its dependencies are missing), warm numba's cache with a small study
# (its compile is a cold start's, not the table's), then rig mc --workers N, a Dask
# LocalCluster of N single-threaded workers and N numba threads in one process at each N of
# COUNTS, with each one's parallel efficiency against 2 (rig/bench/mc_scaling.py), once for
# each batch size of BATCHES (a smaller batch tells whether memory traffic caps the workers).
#
#   bench/device_mc_scaling.sh                    # N = 1 2 4 8 16
#   COUNTS="1 2" BATCHES=256 bench/device_mc_scaling.sh   # a small machine
#   VARY="striker.velocity=normal(0.89 m/s, 0.01 m/s)" bench/device_mc_scaling.sh  # another study
#
# VARY: the study's --vary expressions, separated by ';' (default: rig bench mc's, striker speed and
# every bead's mass); PYTHON: the interpreter to use (default python3); WHEELS: a folder of wheels to install
# from without an index; OUT: a folder for mc_scaling.json and the log (default: a temporary one).
set -euo pipefail
cd "$(dirname "$0")/.."
COUNTS=${COUNTS:-"1 2 4 8 16"}  # 1: the serial share of a batch in one process (the Amdahl line)
VARY=${VARY:-}  # empty: rig bench mc's study
BATCHES=${BATCHES:-"256 64"}  # rig mc's default batch, and a batch whose arrays stay in a core's share of cache
OUT=${OUT:-$(mktemp -d)}
PYTHON=${PYTHON:-python3}
mkdir -p "$OUT"
log() { echo "[$(date +%T)] $*" | tee -a "$OUT/log.txt"; }

if ! "$PYTHON" -c "import numba, h5py, scipy, pint, tqdm, dask.distributed" 2>/dev/null; then
    log "installing the rig and Dask into .venv-scaling"
    "$PYTHON" -m venv .venv-scaling
    PYTHON=$PWD/.venv-scaling/bin/python
    "$PYTHON" -m pip install -q ${WHEELS:+--no-index --find-links "$WHEELS"} ".[dask]" 2>&1 | tail -3
fi
export PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH}  # this tree's rig, installed or not
log "$("$PYTHON" -c 'import os, numba; print(f"python ok, numba {numba.__version__}, {os.cpu_count()} cores")')"

log "warming numba's cache: a 512-shot study on 2 workers"
warm=$(mktemp -d)
timeout 300 "$PYTHON" -c "import sys; from rig.cli import main; sys.exit(main(sys.argv[1:]))" mc ptfe52_magnetic --shots 512 --batch 256 --workers 2 --quiet \
    --vary "striker.velocity=normal(0.89 m/s, 0.01 m/s)" --out "$warm/study" >> "$OUT/log.txt"
rm -rf "$warm"

log "scaling tables at N = $COUNTS, batches of $BATCHES"
cat > "$OUT/scaling.py" <<'PY'  # a file, not stdin: worker processes import the main module
import json, os
from rig.bench import mc, mc_scaling
from rig.bench.baseline import machine

if __name__ == "__main__":  # Dask's and the pool's worker processes import this file again
    print(f"machine: {machine()}")
    vary = tuple(v.strip() for v in os.environ["VARY"].split(";") if v.strip()) or mc.VARY
    print(f"study: ptfe52_magnetic, varied: {'; '.join(vary)}")
    tables = {}
    for batch in [int(b) for b in os.environ["BATCHES"].split()]:
        tables[batch] = mc_scaling.run(vary, batch, [int(n) for n in os.environ["COUNTS"].split()])
        print(mc_scaling.table(tables[batch]), flush=True)
    with open(os.path.join(os.environ["OUT"], "mc_scaling.json"), "w") as fh:
        json.dump({"machine": machine(), "vary": vary, "tables": tables}, fh, indent=1)
PY
VARY="$VARY" COUNTS="$COUNTS" BATCHES="$BATCHES" OUT="$OUT" timeout 360 "$PYTHON" "$OUT/scaling.py" 2>&1 | tee -a "$OUT/log.txt"
log "done: $OUT/mc_scaling.json"
