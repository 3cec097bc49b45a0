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
