"""The analysis reads top-down: pipeline.py calls the stages in order (condition, find and
refine, judge, report), and each module imports only the modules below it in ``DOWN``, so a
reader who starts at the pipeline never has to turn back to a module above."""
import ast
from pathlib import Path

import instruments.analysis

HERE = Path(instruments.analysis.__file__).parent
DOWN = ("batch", "pipeline", "judge", "verdicts", "distortion", "find", "refine", "condition", "setup",
        "plausibility", "pulse", "report")


def _siblings(module: str) -> set:
    """The modules of instruments/analysis/ (not _kernels) that ``module`` imports."""
    out = set()
    for node in ast.walk(ast.parse((HERE / f"{module}.py").read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:  # from .m import x, or from . import m
            out.update([node.module.split(".")[0]] if node.module else [a.name for a in node.names])
    return out - {"_kernels"}


def test_every_module_of_the_analysis_has_its_place():
    assert sorted(p.stem for p in HERE.glob("*.py") if p.stem != "__init__") == sorted(DOWN)


def test_each_module_imports_only_the_modules_below_it():
    wrong = [f"{m} imports {s}" for k, m in enumerate(DOWN) for s in _siblings(m) if s not in DOWN[k + 1:]]
    assert wrong == []


def test_the_pipeline_calls_the_stages_in_order():
    source = (HERE / "pipeline.py").read_text()
    order = [source.index(f"{call}(") for call in ("record_forces", "record_noise", "leading_pair", "report_of")]
    assert order == sorted(order)
