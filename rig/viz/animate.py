"""Off-screen animations of a virtual shot (`rig animate`), rendered with pyvista.

The picture is the rig laid on its side, the striker on the left, the wall on the right
(the real tube stands vertically, striker on top): the translucent holder tube, the ring
magnet around the magnetic bead, the beads as spheres coloured by their average contact
force (N), the striker, the wall and its sensor. Displacements from the static
equilibrium are multiplied by ``exaggerate`` (stated on screen). Below it, the scope's
channels drawn up to the frame's time.

The solver records positions at the frame rate only here (SaveAt.frame_interval); pyvista,
VTK and imageio are imported only when an animation is made. One plotter and one
matplotlib figure are reused for every frame. Without a display VTK renders through EGL
(VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow).
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from instruments.files import atomic_write
from rig.errors import RigError, invalid
from rig.viz.movie_cost import check_options

FORMATS = (".mp4", ".gif", ".png")
WIDTH, VIEW_HEIGHT, PANEL_HEIGHT = 1280, 420, 300
FPS = 20


def check_output(path) -> Path:
    """The output path, refused before any work if its format or folder is wrong."""
    p = Path(path)
    if p.suffix.lower() not in FORMATS:
        raise invalid("--out", str(path), f"a file ending in {', '.join(FORMATS)}")
    if not p.parent.is_dir():
        raise invalid("--out", str(path), f"a file in an existing folder ({p.parent} does not exist)")
    return p


@dataclass(frozen=True)
class Frames:
    """What is drawn: times (s), centres (frames, bodies; m along the tube, striker's far
    end first when there is one), average bead forces (frames, beads; N), displacements
    from the static equilibrium (frames, bodies; m)."""

    times: np.ndarray
    centres: np.ndarray
    bead_force: np.ndarray
    displacement: np.ndarray


def chain_frames(rig, n_frames: int) -> Frames:
    """Solve the rig's shot recording positions at n_frames instants over its duration,
    and install the solution in the rig (its instruments read the same solve)."""
    from rig.model.contact import hertz_force
    from rig.solver.problem import ChainProblem
    from rig.solver.run import frame_origin
    from rig.solver.solve import solve

    duration = rig.solver.duration
    rec = rig.save_at()
    rec = replace(rec, frame_interval=duration / max(n_frames - 1, 1))
    problem = ChainProblem.from_chain(rig.chain)
    sol = solve(problem, duration, save=rec, method=rig.solver.method, accuracy=rig.solver.accuracy)
    rig.use_solution(sol)
    assert sol.frames is not None, "frames were asked for (frame_interval)"
    pos = sol.frames[:n_frames]
    u = pos - frame_origin(rig.chain)  # displacements from the static equilibrium (m)
    off, beads = problem.offset, len(rig.chain.beads)
    # a compliant wall's plate is not in the frames: drawn at rest (it colours the last bead only)
    u_all = np.concatenate([u, np.zeros((u.shape[0], problem.n_bodies - u.shape[1]))], axis=1)
    # elastic contact force of every slot (slot i: bodies i-1 and i; slot 0 and a missing wall: 0)
    slots = np.zeros((u.shape[0], problem.n_bodies + 1))
    slots[:, 1:problem.n_bodies] = hertz_force(problem.A[None, 1:], problem.d0[None, 1:] + u_all[:, :-1] - u_all[:, 1:],
                                                 problem.expo[None, 1:])
    above, below = slots[:, off: off + beads], slots[:, off + 1: off + 1 + beads]
    return Frames(np.arange(pos.shape[0]) * rec.frame_interval, pos, 0.5 * (above + below), u)


class _View:
    """The 3-D scene: built once, moved and recoloured for every frame."""

    def __init__(self, rig, frames: Frames, exaggerate: float):
        import pyvista as pv

        chain, off = rig.chain, int(rig.chain.striker is not None)
        self.off, self.exaggerate = off, exaggerate
        self.x_eq = frames.centres[0]
        radii = np.array([b.radius for b in chain.beads])
        sphere = pv.Sphere(radius=1.0, theta_resolution=18, phi_resolution=12)
        n_pts, tri = sphere.n_points, sphere.faces.reshape(-1, 4)
        self.n_pts = n_pts
        self.unit = np.tile(sphere.points, (len(radii), 1)) * np.repeat(radii, n_pts)[:, None]
        self.owner = np.repeat(np.arange(len(radii)), n_pts)
        faces = np.concatenate([np.column_stack([tri[:, :1], tri[:, 1:] + k * n_pts]) for k in range(len(radii))])
        self.beads = pv.PolyData(self._bead_points(self.x_eq[off:]), faces.ravel())
        self.beads["average contact force (N)"] = np.zeros(self.beads.n_points)
        self.p = pv.Plotter(off_screen=True, window_size=(WIDTH, VIEW_HEIGHT))
        self.p.set_background("white")
        top_force = float(np.nanmax(frames.bead_force))
        self.p.add_mesh(self.beads, scalars="average contact force (N)", cmap="inferno",
                        clim=(0.0, max(top_force, 1e-9)), smooth_shading=True,
                        scalar_bar_args={"title": "average contact force (N)", "color": "black",
                                         "vertical": False, "position_x": 0.62, "position_y": 0.04,
                                         "width": 0.35, "height": 0.1, "fmt": "%.1f"})
        r_bore = 0.5 * rig.holder.bore
        x_last = self.x_eq[-1] + radii[-1]
        self.striker = None
        x_left = self.x_eq[off] - radii[0]
        if off:
            s = chain.striker
            x_left = self.x_eq[0] - 0.3 * s.length
            self.striker = pv.Cylinder(center=(self.x_eq[0] + 0.5 * s.length, 0, 0), direction=(1, 0, 0),
                                       radius=0.5 * s.diameter, height=s.length, resolution=32)
            self.striker_base = self.striker.points.copy()
            self.p.add_mesh(self.striker, color="lightsteelblue", smooth_shading=True)
        tube_len = x_last - x_left
        tube = pv.CylinderStructured(radius=[r_bore, 0.5 * rig.holder.outer_diameter], height=tube_len,
                                     center=(x_left + 0.5 * tube_len, 0, 0), direction=(1, 0, 0),
                                     theta_resolution=48, z_resolution=2).extract_surface(algorithm=None)
        self.p.add_mesh(tube, color="lightblue", opacity=0.12)
        if rig.magnet is not None:
            ring = pv.CylinderStructured(radius=[0.6 * rig.holder.outer_diameter, 1.4 * rig.holder.outer_diameter],
                                         height=2.5 * radii[0], center=(self.x_eq[off], 0, 0), direction=(1, 0, 0),
                                         theta_resolution=48, z_resolution=2).extract_surface(algorithm=None)
            self.p.add_mesh(ring, color="dimgray", opacity=0.35)
        if chain.wall is not None:
            w = 2.0 * rig.holder.outer_diameter
            self.p.add_mesh(pv.Box((x_last, x_last + 0.4 * w, -w, w, -w, w)), color="darkgoldenrod")
            if rig.wall_sensor is not None:
                self.p.add_mesh(pv.Box((x_last - 0.2 * radii[-1], x_last, -r_bore, r_bore, -r_bore, r_bore)),
                                color="seagreen")
        self.p.add_text(f"displacements x {exaggerate:.3g}   (tube vertical in the rig: striker on top)",
                        position="upper_left", font_size=10, color="black")
        self.clock = self.p.add_text("t = 0.000 ms", position="upper_right", font_size=12, color="black")
        for g in rig.gauges:  # mark the gauge beads with their channels
            self.p.add_point_labels([(self.x_eq[off + g.bead], 0, 3.0 * radii[0])], [f"{g.channel} ({g.name})"],
                                    font_size=11, point_size=1, shape_opacity=0.0, text_color="black")
        self.p.view_xz()
        self.p.enable_parallel_projection()
        x_right = x_last + 0.8 * rig.holder.outer_diameter
        centre = 0.5 * (x_left + x_right)
        self.p.camera.focal_point = (centre, 0.0, 0.0)
        self.p.camera.position = (centre, -1.0, 0.0)
        self.p.camera.up = (0.0, 0.0, 1.0)
        self.p.camera.parallel_scale = 0.55 * (x_right - x_left) * VIEW_HEIGHT / WIDTH

    def _bead_points(self, centres):
        pts = self.unit.copy()
        pts[:, 0] += centres[self.owner]
        return pts

    def render(self, frames: Frames, k: int) -> np.ndarray:
        x = self.x_eq + self.exaggerate * frames.displacement[k]
        self.beads.points = self._bead_points(x[self.off:])
        self.beads["average contact force (N)"] = np.repeat(frames.bead_force[k], self.n_pts)
        if self.striker is not None:
            pts = self.striker_base.copy()
            pts[:, 0] += x[0] - self.x_eq[0]
            self.striker.points = pts
        self.clock.set_text("upper_right", f"t = {frames.times[k] * 1e3:.3f} ms")
        self.p.render()
        return np.asarray(self.p.screenshot(return_img=True))[:, :, :3]

    def close(self):
        self.p.close()


class _Traces:
    """The scope's channels (V) against the shot's time, drawn up to the frame's time."""

    def __init__(self, record, duration: float):
        import matplotlib

        matplotlib.use("Agg", force=False)
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.fig = Figure(figsize=(WIDTH / 100, PANEL_HEIGHT / 100), dpi=100)
        self.canvas = FigureCanvasAgg(self.fig)
        ax = self.fig.add_axes((0.06, 0.18, 0.92, 0.74))
        self.series = []
        t0 = record.trigger_time or 0.0
        lo, hi = 0.0, 0.0
        for ch, w in record.waveforms.items():
            t, v = w.time() + t0, w.volts()
            line, = ax.plot([], [], lw=1.0, label=ch)
            self.series.append((line, t * 1e3, v))
            lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
        ax.set_xlim(0.0, duration * 1e3)
        pad = 0.05 * (hi - lo or 1.0)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_xlabel("time after impact (ms)")
        ax.set_ylabel("scope (V)")
        if self.series:
            ax.legend(loc="upper right", fontsize=8)
        self.now = ax.axvline(0.0, color="gray", lw=0.8)

    def render(self, t: float) -> np.ndarray:
        for line, tm, v in self.series:
            n = int(np.searchsorted(tm, t * 1e3, side="right"))
            line.set_data(tm[:n], v[:n])
        self.now.set_xdata([t * 1e3, t * 1e3])
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[:, :, :3].copy()


def default_exaggeration(frames: Frames, rig) -> float:
    """A factor that moves the most displaced bead by a third of a diameter (at least 1)."""
    top = float(np.max(np.abs(frames.displacement[:, int(rig.chain.striker is not None):])))
    return max(1.0, (rig.chain.beads[0].diameter / 3.0) / top) if top > 0 else 1.0


def animate(rig, out, frames: int = 100, exaggerate: float | None = None, seed: int | None = None,
            progress=None) -> dict:
    """Render the rig's shot to ``out`` (.mp4, .gif: ``frames`` frames; .png: one still, the
    one of ``frames`` instants over the duration nearest the time the leading pulse passes
    the last gauge, else the middle one). Returns a summary: "frames" written, "instants"
    the shot was recorded at, and for a still its time "still_time_s" and why that one
    ("still_at")."""
    out = check_output(out)
    check_options(frames, exaggerate)
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    t_start = time.perf_counter()
    fr = chain_frames(rig, frames)
    shot = rig.fire(seed=seed, truth=False)
    x = default_exaggeration(fr, rig) if exaggerate is None else float(exaggerate)
    view = _View(rig, fr, x)
    traces = _Traces(shot.scope, rig.solver.duration)
    still = out.suffix.lower() == ".png"
    order: list[int] | range
    if still:
        k, still_at = _still_frame(rig, fr)
        order = [k]
    else:
        order = range(len(fr.times))
    def encoded() -> bytes:
        """The image or movie, encoded in memory: a writer that fails on a full disk
        retries its flush when it is collected, a traceback after the error line."""
        import io

        import imageio.v2 as imageio

        buf, kind = io.BytesIO(), out.suffix.lower()
        if still:
            k = order[0]
            imageio.imwrite(buf, np.vstack([view.render(fr, k), traces.render(fr.times[k])]), format=kind)
        else:
            kw = {"fps": FPS, "macro_block_size": 8} if kind == ".mp4" else {"duration": 1000 / FPS, "loop": 0}
            with imageio.get_writer(buf, format=kind, **kw) as writer:
                for k in order:
                    writer.append_data(np.vstack([view.render(fr, k), traces.render(fr.times[k])]))
                    if progress:
                        progress()
        return buf.getvalue()

    try:
        data = encoded()
        atomic_write(out, lambda tmp: Path(tmp).write_bytes(data))  # no half-written movie, an earlier one kept
    finally:
        view.close()
    summary = {"out": str(out), "frames": 1 if still else len(fr.times), "instants": len(fr.times),
               "exaggerate": x, "seed": shot.seed, "duration_s": rig.solver.duration,
               "seconds": time.perf_counter() - t_start}
    if still:
        summary.update(still_time_s=float(fr.times[order[0]]), still_at=still_at)
    return summary


def _still_frame(rig, fr: Frames) -> tuple:
    """(index of the still among the frames' instants, the time it stands for, in words)."""
    lead = rig.truth_analysis().leading if len(rig.gauges) >= 2 else {}
    last = lead.get("lower") or lead.get("upper")
    t = last["time"] if last else 0.5 * fr.times[-1]
    return int(np.argmin(np.abs(fr.times - t))), ("the leading pulse at the last gauge" if last
                                                   else "the middle of the shot")


def require_renderer(out: str | None = None):
    """pyvista and imageio (and imageio-ffmpeg for an ``out`` movie .mp4), or a one-line
    error saying how to get them (the ``animate`` extra)."""
    try:
        import imageio  # noqa: F401 - imported to find whether the extra is installed
        import pyvista  # noqa: F401 - the same

        if out is not None and str(out).lower().endswith(".mp4"):
            import imageio_ffmpeg  # noqa: F401 - the same
    except ImportError as exc:
        raise RigError(f"rig animate needs the animate extra ({exc.name} is missing): "
                       f"pip install \"sonic-rig[animate]\"") from None
