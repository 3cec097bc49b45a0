"""The benchmarks name the machine their figures come from: its CPU and its vector width,
on which the kernels' floor (the vectorised square roots) depends."""
import os

from rig.bench import accuracy
from rig.bench.baseline import machine

CPUINFO = """processor\t: 0
model name\t: {model}
flags\t\t: fpu sse2 {flags}

processor\t: 1
model name\t: {model}
flags\t\t: fpu sse2 {flags}
"""


def test_machine_names_the_cpu_and_its_widest_vector_extension(tmp_path):
    for flags, width in (("avx avx2 fma avx512f avx512dq", "AVX-512"), ("avx avx2 fma", "AVX2"), ("avx", "no AVX2")):
        info = tmp_path / "cpuinfo"
        info.write_text(CPUINFO.format(model="Some EPYC 9004", flags=flags))
        assert machine(str(info)).startswith(f"Some EPYC 9004, {width} ({os.cpu_count()} cores)")


def test_machine_without_cpuinfo_still_answers(tmp_path):
    assert f"({os.cpu_count()} cores)" in machine(str(tmp_path / "absent"))


def test_accuracy_table_says_which_machine_its_cpu_column_comes_from():
    row = dict(case="c", setting=1e-4, error=3e-5, estimate=3.3e-5, steps=10, cpu_s=0.1, dt_s=1e-7, attempts=2,
               single_solve_cpu_s=0.02, estimate_from_2dt=3e-5)
    text = accuracy.table({"rows": [row], "reference_check": {"c": 1e-9}, "machine": "Some EPYC, AVX2 (2 cores)"})
    assert "error within [setting/10, setting]: 1 of 1" in text
    assert text.splitlines()[-1].startswith("machine: Some EPYC, AVX2 (2 cores)")
