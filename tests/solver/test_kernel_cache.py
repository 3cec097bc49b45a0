"""numba's on-disk cache follows every source of a kernel package, not only a kernel's own
file (a caller inlines its callees from the package's other files)."""
import subprocess
import sys
import textwrap


def _package(root, value):
    pkg = root / "kern"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("from numerics.jit import drop_stale_cache\n\n"
                                     "drop_stale_cache(__name__)\n")
    (pkg / "callee.py").write_text(textwrap.dedent(f"""
        from numba import njit

        @njit(cache=True)
        def value():
            return {value}
    """))
    (pkg / "caller.py").write_text(textwrap.dedent("""
        from numba import njit
        from .callee import value

        @njit(cache=True)
        def twice():
            return 2.0 * value()
    """))


def _run(root):
    code = "from kern.caller import twice; print(twice())"
    out = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, check=True)
    return float(out.stdout)


def test_a_changed_callee_in_another_file_is_not_served_stale(tmp_path):
    _package(tmp_path, 1.5)
    assert _run(tmp_path) == 3.0
    assert _run(tmp_path) == 3.0  # from the cache
    _package(tmp_path, 2.5)       # only the callee's file changes
    assert _run(tmp_path) == 5.0  # numba alone would load the caller's stale 3.0
