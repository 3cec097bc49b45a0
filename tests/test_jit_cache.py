"""Every compiled function of the project lives in a kernel package whose cached machine
code is dropped when any of the package's sources changes (numerics/jit.drop_stale_cache).
numba keys a cached function on its own file only: a kernel compiled elsewhere that calls
a kernel of another file keeps the old callee's code after that file changes (a batched
analysis, now instruments/analysis/batch.py, once went on running the median and
cross-correlation it was compiled with). Read with ``ast`` from every .py file under rig/,
instruments/ and numerics/; the checker is tested on a planted tree."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DECORATORS = {"jit", "njit"}


def _compiled(tree: ast.Module) -> list:
    """Names of the functions decorated with jit or njit (called or not, plain or as numba.x)."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            for d in node.decorator_list:
                target = d.func if isinstance(d, ast.Call) else d
                if getattr(target, "id", getattr(target, "attr", None)) in DECORATORS:
                    out.append(node.name)
    return out


def unguarded(root: Path) -> list:
    """'path: function' of each compiled function outside a package that calls drop_stale_cache."""
    bad = []
    for pkg in ("rig", "instruments", "numerics"):
        for path in sorted((root / pkg).rglob("*.py")):
            names = _compiled(ast.parse(path.read_text()))
            init = path.parent / "__init__.py"
            guarded = init.is_file() and "drop_stale_cache(__name__" in init.read_text()
            if names and not guarded:
                bad += [f"{path.relative_to(root)}: {n}" for n in names]
    return bad


def test_every_compiled_function_is_in_a_guarded_kernel_package():
    assert unguarded(ROOT) == []


def test_the_checker_finds_a_planted_kernel(tmp_path):
    kernels = tmp_path / "instruments" / "_kernels"
    kernels.mkdir(parents=True)
    (kernels / "__init__.py").write_text("from numerics.jit import drop_stale_cache\n\ndrop_stale_cache(__name__)\n")
    (kernels / "ok.py").write_text("@jit\ndef fine(x):\n    return x\n")
    (tmp_path / "instruments" / "__init__.py").write_text("")
    (tmp_path / "instruments" / "batch.py").write_text(
        "@jit(parallel=True)\ndef loose(x):\n    return x\n\n@numba.njit\ndef other(x):\n    return x\n")
    (tmp_path / "rig").mkdir()
    assert unguarded(tmp_path) == ["instruments/batch.py: loose", "instruments/batch.py: other"]


SAVE_ON_A_FULL_DISK = """
import logging, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
sys.dont_write_bytecode = True  # a .pyc written past the limit would be truncated (tests/cli/test_full_disk.py)
resource.setrlimit(resource.RLIMIT_FSIZE, (200, 200))  # no cache file fits: each save fails with EFBIG
logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
import numpy as np
from instruments._kernels import pcg64
state = pcg64.seeded(7)
print(int(state[0]) == int(np.random.default_rng(7).bit_generator.state["state"]["state"] >> 64))
"""


def test_a_kernel_whose_machine_code_the_disk_cannot_keep_still_runs(tmp_path):
    """numba's cache on a full disk (here a file-size limit, EFBIG as ENOSPC): the kernel is
    compiled, runs and gives its result; the save's failure is logged, not raised (numba
    itself ends the command with the OSError, numerics.dispatcher.SavedIfRoom), and no
    temporary file is left in the cache folder."""
    import os
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", SAVE_ON_A_FULL_DISK], capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)), cwd=ROOT, check=False)
    assert done.returncode == 0 and done.stdout.strip() == "True", done.stderr[-2000:]
    assert "numba's cache kept no machine code of" in done.stderr and "File too large" in done.stderr
    assert not [p for p in tmp_path.rglob("*") if ".tmp." in p.name]
