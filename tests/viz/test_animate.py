"""Off-screen animations: the frames themselves, the output checks, the lazy import."""
import json
import subprocess
import sys

import numpy as np
import pytest

from rig.cli import main

SMALL = ["--set", "chain.beads=20", "--set", "gauges.upper.bead=6", "--set", "gauges.lower.bead=12",
         "--set", "solver.duration=0.5 ms", "--set", "scope.record_length=2000"]


def _frames(path):
    import imageio.v2 as imageio

    return np.stack([np.asarray(f)[..., :3] for f in imageio.mimread(path)])


@pytest.fixture(scope="module")
def movie(tmp_path_factory):
    pytest.importorskip("pyvista")
    out = tmp_path_factory.mktemp("anim") / "shot.gif"
    assert main(["animate", "ptfe52_magnetic", *SMALL, "--seed", "4", "--frames", "12",
                 "--exaggerate", "20", "--out", str(out), "--quiet"]) == 0
    return _frames(out)


def test_movie_has_the_requested_frames_and_they_are_not_blank(movie):
    from rig.viz.animate import PANEL_HEIGHT, VIEW_HEIGHT, WIDTH

    assert movie.shape == (12, VIEW_HEIGHT + PANEL_HEIGHT, WIDTH, 3)
    for frame in movie:
        assert frame.std() > 10  # beads, tube, text and traces, not a flat background


def test_colour_moves_down_the_chain_with_the_wave(movie):
    # along the chain's row in the 3-D view, the column that warmed most (largest force on
    # the 'inferno' map) moves right, from the striker towards the wall, as the pulse travels
    from rig.viz.animate import VIEW_HEIGHT

    view = movie[:, :VIEW_HEIGHT].astype(float)
    row = view[:, VIEW_HEIGHT // 2 - 3: VIEW_HEIGHT // 2 + 3]  # the chain's axis
    warm = row[..., 0] - row[..., 2]  # red - blue: 0 on white and grey, high on the orange of a loaded bead
    warm = warm - warm[0]  # against the first frame: the still parts (wall, magnet, striker) cancel
    cols = warm.max(axis=1).argmax(axis=1)
    moving = cols[2:9]  # while the leading pulse crosses (the first frames still show the impact)
    assert np.all(np.diff(moving) > 0), cols
    assert not np.array_equal(movie[3], movie[8])  # colours change as the pulse passes


def test_still_png(tmp_path, capsys):
    """A still is one frame, picked among --frames instants: the line says so (it had said
    "1 frame(s)" of a --frames 10)."""
    pytest.importorskip("pyvista")
    import imageio.v2 as imageio

    out = tmp_path / "still.png"
    assert main(["animate", "ptfe52_magnetic", *SMALL, "--seed", "1", "--frames", "10", "--out", str(out)]) == 0
    assert np.asarray(imageio.imread(out)).std() > 10
    line = capsys.readouterr().out
    assert "a still at t = " in line and "nearest of 10 instants (--frames)" in line, line
    assert main(["animate", "ptfe52_magnetic", *SMALL, "--seed", "1", "--frames", "10", "--out", str(out),
                 "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["frames"] == 1 and summary["instants"] == 10
    assert 0 < summary["still_time_s"] < summary["duration_s"]


@pytest.mark.parametrize("out,message", [("shot.avi", "ending in .mp4, .gif, .png"),
                                         ("missing/shot.mp4", "does not exist")])
def test_bad_output_is_refused_before_rendering(tmp_path, capsys, monkeypatch, out, message):
    import rig.experiment.scene

    def no_solving(*a, **k):
        raise AssertionError("nothing may be computed for a bad --out")

    monkeypatch.setattr(rig.experiment.scene, "load", no_solving)
    assert main(["animate", "ptfe52_magnetic", "--out", str(tmp_path / out)]) == 2
    err = capsys.readouterr().err
    assert message in err and "--out" in err and len(err.strip().splitlines()) == 1


def test_the_rig_does_not_import_pyvista():
    code = ("import sys, rig, rig.experiment.shot, rig.solver.solve, rig.study.mc_run, rig.cli; "
            "print('pyvista' in sys.modules or 'vtk' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "False"


def test_a_movie_without_the_animate_extra_is_refused_in_one_line(monkeypatch):
    import sys

    from rig.errors import RigError
    from rig.viz.animate import require_renderer

    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # as if not installed
    with pytest.raises(RigError, match=r'imageio_ffmpeg is missing\): pip install "sonic-rig\[animate\]"'):
        require_renderer("shot.mp4")
