"""Every benchmark module imports (a module no other test touches, such as rig/bench/mc.py,
would otherwise reach `rig bench` with a syntax error), each with its docstring."""
import importlib
import pkgutil

import pytest

import rig.bench


@pytest.mark.parametrize("name", sorted(m.name for m in pkgutil.iter_modules(rig.bench.__path__) if not m.ispkg))
def test_the_bench_module_imports(name):
    module = importlib.import_module(f"rig.bench.{name}")
    assert module.__doc__


def test_the_mc_snippet_runs_this_batch_size():
    from rig.bench import mc
    from rig.study.mc_spec import DEFAULT_BATCH

    compile(mc.SNIPPET, "snippet", "exec")
    assert f"mc.BATCH = {DEFAULT_BATCH}" in mc.SNIPPET
