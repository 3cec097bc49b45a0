"""The command line starts light: help, the version and a scene error load none of the
heavy libraries (checked in a fresh interpreter); the shot path loads no scipy.signal."""
import json
import subprocess
import sys

import pytest

import rig

HEAVY = ("numba", "scipy", "pint", "pyvista", "vtk", "matplotlib", "dask", "h5py")
PROBE = ("import json, sys\nfrom rig.cli import main\ntry:\n    code = main({argv!r})\nexcept SystemExit as e:\n"
         "    code = e.code\nprint(json.dumps([code, sorted(m for m in {heavy!r} if m in sys.modules)]))")


def _run(argv, heavy=HEAVY):
    out = subprocess.run([sys.executable, "-c", PROBE.format(argv=argv, heavy=heavy)],
                         capture_output=True, text=True, check=True)
    return out, json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("argv,code", [(["--help"], 0), (["shot", "--help"], 0), (["--version"], 0),
                                       (["shot", "nosuchscene"], 2), (["mc", "nosuchscene", "--shots", "4",
                                                                       "--out", "x"], 2)])
def test_help_version_and_scene_errors_load_nothing_heavy(argv, code):
    out, (got, loaded) = _run(argv)
    assert got == code and loaded == [], (out.stderr, loaded)


def test_version():
    out, _ = _run(["--version"])
    assert out.stdout.startswith(f"rig {rig.__version__}")


def test_a_shot_loads_no_scipy_signal_nor_pint():
    _, (code, loaded) = _run(["shot", "ptfe52_magnetic", "--seed", "1"], ("scipy.signal", "scipy.stats", "pint",
                                                                          "matplotlib", "h5py", "dask"))
    assert code == 0 and loaded == []


@pytest.mark.parametrize("argv", [["sweep", "nosuchscene", "--vary", "striker.velocity=1:2:2"],
                                  ["animate", "nosuchscene", "--out", "x.mp4"]])
def test_other_commands_check_the_scene_first(argv):
    _, (code, loaded) = _run(argv)
    assert code == 2 and loaded == []


def test_python_m_rig_cli_is_the_command():
    out = subprocess.run([sys.executable, "-m", "rig.cli", "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.startswith("rig ")


def test_another_distributions_instruments_package_is_named_in_one_line(tmp_path):
    """InstrumentKit installs a package called 'instruments' too: where that one is the
    package Python finds and the rig's modules are not found under it, every command had
    failed deep in an import. The command says so in one line, exit 2, naming where the
    other package lies (a process whose path finds a stand-in first, without site-packages)."""
    import subprocess
    import sys
    from pathlib import Path

    other = tmp_path / "instruments"
    other.mkdir()
    (other / "__init__.py").write_text('"""Another distribution\'s instruments package."""\n')
    root = Path(__file__).resolve().parents[2]
    run = subprocess.run([sys.executable, "-S", "-c", "import sys; from rig.cli import main; "
                                                      "sys.exit(main(['--version']))"],
                         capture_output=True, text=True, timeout=60, cwd=tmp_path,
                         env={"PYTHONPATH": f"{tmp_path}:{root}", "PATH": "/usr/bin:/bin"})
    assert run.returncode == 2 and run.stdout == "", run
    (line,) = run.stderr.strip().splitlines()
    assert line.startswith("rig: error: the import name 'instruments' is") and str(other) in line, line
    assert "a virtual environment of its own" in line
