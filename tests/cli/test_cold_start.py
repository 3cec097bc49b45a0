"""A cold start: the first `rig shot` with an empty numba cache says in one line what it
compiles, compiles the instruments' kernels in a side process
(instruments/precompile.py) and gives the bits of a warm shot; the side process compiles
exactly the signatures the shot calls (else the main process would compile them again, and
the side process be waste); a Hertz shot compiles no other law's code (the law reaches the
kernels as a constant, numerics/dispatcher.py), and a shot without drag, friction or
viscous contacts no dissipation (bundles.Holder.flows, another such constant)."""
import json
import os
import subprocess
import sys

from numba.core.sigutils import normalize_signature

from instruments.precompile import SHOT, SHOT_SMALL, STUDY, STUDY_SMALL, compile_now, kernel
from rig.cli import main

SHOT_ARGS = ["shot", "ptfe52_magnetic", "--seed", "1", "--json"]


# a cold shot in a fresh process, then the side kernels the main process did not load from numba's cache
# (it compiled them itself, or compiled another copy: a signature out of step), then the Thornton
# law's kernels it compiled, the dissipation's, and the numba functions it compiled that format text
COLD_SHOT = ("import json\nfrom instruments.precompile import SHOT, SHOT_SMALL, kernel\nfrom rig.cli import main\n"
             "from numba.core import event\ncompiled = set()\n"
             "class Compiled(event.Listener):\n"
             "    def on_start(self, ev):\n"
             "        f = ev.data['dispatcher'].py_func\n"
             "        compiled.add(f'{{f.__module__}}.{{f.__qualname__}}')\n"
             "    def on_end(self, ev):\n"
             "        pass\n"
             "event.register('numba:compile', Compiled())\n"
             "from rig.model.laws import thornton\ncode = main({argv!r})\n"
             "print(json.dumps(sorted(n for n in {{**SHOT, **SHOT_SMALL}}\n"
             "    if sum(kernel(n).stats.cache_misses.values()) or len(kernel(n).signatures) != 1)))\n"
             "print(json.dumps(sorted(n for n, f in vars(thornton).items() if getattr(f, 'signatures', None))))\n"
             "from rig.solver.kernels import dissipation\n"
             "print(json.dumps(sorted(n for n, f in vars(dissipation).items() if getattr(f, 'signatures', None))))\n"
             "print(json.dumps(sorted(n for n in compiled if 'unicode' in n or 'shape_context' in n)))")


def test_the_side_process_compiles_the_signatures_a_shot_calls_from_python(capsys):
    compile_now({**SHOT, **SHOT_SMALL})
    assert main(SHOT_ARGS) in (0, None)
    for name, signature in {**SHOT, **SHOT_SMALL}.items():
        assert kernel(name).signatures == [normalize_signature(signature)[0]], name


def test_the_side_process_compiles_the_signatures_a_study_calls_from_python(tmp_path, monkeypatch):
    """And a study calls no single-shot kernel: its nominal solves run through the batched
    kernel (rig.solver.ensemble.solved_as_batches), so a cold study compiles one chain kernel."""
    from rig.solver import run

    single = []
    monkeypatch.setattr(run, "integrate", lambda *args: single.append(args))
    compile_now({**STUDY, **STUDY_SMALL})
    assert main(["mc", "ptfe52_magnetic", "--vary", "striker.velocity=normal(0.89 m/s, 0.01 m/s)", "--shots", "4",
                 "--batch", "4", "--out", str(tmp_path / "study"), "--quiet"]) in (0, None)
    assert single == []
    for name, signature in {**STUDY, **STUDY_SMALL}.items():
        assert kernel(name).signatures == [normalize_signature(signature)[0]], name


def test_a_cold_shot_says_what_it_compiles_once_compiles_nothing_twice_and_has_the_warm_bits(tmp_path):
    warm = subprocess.run([sys.executable, "-m", "rig.cli", *SHOT_ARGS], capture_output=True, text=True, check=True)
    cold, said = _on_a_terminal([sys.executable, "-c", COLD_SHOT.format(argv=SHOT_ARGS)],
                                dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    lines = said.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rig shot: numba is compiling the chain solver and the "
                                                   "instruments (in two processes)"), said
    *shot, compiled_twice, thornton, dissipation, text = cold.stdout.strip().splitlines()
    assert json.loads(compiled_twice) == []
    assert json.loads(thornton) == []  # the scene's contacts are Hertz's
    assert "dissipate" not in json.loads(dissipation)  # and without flows (bundles.Holder.flows)
    # no array assigned to a slice: numba would compile the shape-mismatch message's formatting (about 1.5 s)
    assert json.loads(text) == []
    assert _bits(json.loads("\n".join(shot))) == _bits(json.loads(warm.stdout))
    again, said = _on_a_terminal([sys.executable, "-m", "rig.cli", *SHOT_ARGS],
                                 dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    assert said == "" and _bits(json.loads(again.stdout)) == _bits(json.loads(warm.stdout))  # warm now: nothing said


def _on_a_terminal(cmd, env):
    """(the finished process, its stderr) of ``cmd`` run with its stderr on a pseudo-terminal."""
    import pty

    main_end, child_end = pty.openpty()
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=child_end, text=True, env=env, check=True)
    os.close(child_end)
    said = b""
    while True:
        try:
            chunk = os.read(main_end, 4096)
        except OSError:  # the terminal's other end is closed: all is read
            break
        if not chunk:
            break
        said += chunk
    os.close(main_end)
    return done, said.decode().replace("\r\n", "\n")


def _bits(out):
    """A shot's JSON less its timings (wall_s)."""
    if isinstance(out, dict):
        return {k: _bits(v) for k, v in out.items() if k != "wall_s"}
    return [_bits(v) for v in out] if isinstance(out, list) else out


def test_a_side_process_never_outlives_its_command():
    """finish(), registered at exit by precompile.start: a side process that ends within the
    wait is waited for (its compiles kept), one that does not is stopped."""
    from instruments.precompile import finish

    quick = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.2)"])
    finish(quick, wait_s=30.0)
    assert quick.returncode == 0
    slow = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    finish(slow, wait_s=0.5)
    assert slow.returncode is not None and slow.returncode != 0


def test_a_cold_start_says_so_in_a_log_too(monkeypatch, capsys):
    """Output that is no terminal (a log, a pipe, CI) had sat silent for the whole compile:
    the one line is said there too, and not with --quiet (rig mc)."""
    import instruments.precompile
    import numerics.dispatcher
    from rig.cli.common import compile_cold

    monkeypatch.setattr(numerics.dispatcher, "has_machine_code", lambda kernel: False)  # a cold cache
    monkeypatch.setattr(instruments.precompile, "start", lambda kernels, then=None: None)  # no side process
    compile_cold("shot", "shot")
    err = capsys.readouterr().err
    assert err == ("rig shot: numba is compiling the chain solver, once: later runs load the machine code from "
                   "its cache\n"), err
    compile_cold("mc", "study", quiet=True)
    assert capsys.readouterr().err == ""


def test_a_shot_refused_on_a_cold_cache_stops_its_side_process_and_says_one_line(monkeypatch, capsys):
    """The side process starts before the chain is built (its statics compile meanwhile);
    a shot refused there (too large, no --allow-large) stops it at once, and the refusal is
    the command's only line (no word of a compile that will not happen)."""
    import instruments.precompile
    import numerics.dispatcher

    started = []

    def start(kernels, then=None):  # the real start, its process kept to look at
        on = real_start(kernels, then)
        started.extend(set(numerics.dispatcher.SIDE_COMPILES.values()))
        return on

    real_start = instruments.precompile.start
    monkeypatch.setattr(numerics.dispatcher, "has_machine_code", lambda kernel: False)  # a cold cache
    monkeypatch.setattr(instruments.precompile, "start", start)
    assert main(["shot", "ptfe52_magnetic", "--set", "solver.duration=1000 s", "--seed", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--allow-large" in err and "compiling" not in err, err
    assert len(started) == 1 and started[0].returncode is not None  # started, and ended before the command
    assert numerics.dispatcher.SIDE_COMPILES == {}
