"""Figures of the reproduction (matplotlib, Agg backend, PNG; imported only when drawn)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class FigureSpec:
    """A figure as data: the drawing function's name in this module, the PNG's file name
    and the function's arguments after the path."""

    kind: str
    filename: str
    args: tuple


def draw(folder, spec: FigureSpec) -> Path:
    """Draw ``spec`` into folder/spec.filename (PNG)."""
    kinds: dict[str, Callable[..., None]] = {"speed_vs_force": speed_vs_force, "traces": traces,
                                             "beta_curve": beta_curve, "pulse_vs_solitary": pulse_vs_solitary}
    path = Path(folder) / spec.filename
    kinds[spec.kind](path, *spec.args)
    return path


def save(fig, path, dpi: int):
    """``fig`` as the image ``path`` (its format from the suffix), written whole or not at
    all (instruments.files)."""
    from instruments.files import atomic_write

    path = Path(path)
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi))


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def speed_vs_force(path, title, series, theory):
    """series: [(label, F_m array (N), V_s array (m/s), marker)]; theory: dict with Eq curves."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for label, x, y, style in series:
        ax.plot(x, y, style, label=label, ms=6)
    F = theory["F_m"]
    for label, v, style in theory["curves"]:
        ax.plot(F, v, style, label=label, lw=1.3)
    for label, c0, style in theory["sound"]:
        ax.axhline(c0, ls=":", color=style, lw=1.0, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("maximum contact force F_m (N)")
    ax.set_ylabel("solitary wave speed V_s (m/s)")
    ax.set_title(title)
    ax.legend(fontsize=7, loc="lower right")
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    save(fig, path, dpi=130)
    plt.close(fig)


def traces(path, title, panels):
    """panels: {(row label, column label): [(label, t (s), F (N))]} on a 2 x 2 grid, traces
    stacked with an offset like the published figures."""
    plt = _plt()
    rows = sorted({r for r, _ in panels}, key=list(dict.fromkeys(r for r, _ in panels)).index)
    cols = sorted({c for _, c in panels}, key=list(dict.fromkeys(c for _, c in panels)).index)
    fig, axes = plt.subplots(len(rows), len(cols), figsize=(9.5, 6.5), sharex=True, squeeze=False)
    for i, r in enumerate(rows):
        for j, c in enumerate(cols):
            ax = axes[i][j]
            lines = panels.get((r, c), [])
            step = 1.1 * max((np.max(f) for _, _, f in lines), default=1.0)
            for k, (label, t, f) in enumerate(lines):
                ax.plot(t * 1e3, f + (len(lines) - 1 - k) * step, lw=0.9, label=label)
            ax.set_title(f"{r}: {c}", fontsize=9)
            ax.set_ylabel("force (N), offset per trace")
            ax.legend(fontsize=7, loc="upper right")
            ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time (ms)")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save(fig, path, dpi=120)
    plt.close(fig)


def beta_curve(path, fr, beta, points):
    """beta(F_m/F_0) of the discrete chain, with the virtual shots' betas as markers."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    ax.plot(fr, beta, "k-", label="exact discrete solitary wave")
    for label, x, y, style in points:
        ax.plot(x, y, style, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("F_m / F_0")
    ax.set_ylabel("beta = F_d / F_m,e")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    save(fig, path, dpi=130)
    plt.close(fig)


def pulse_vs_solitary(path, title, curves):
    """curves: [(label, t (us), F (N), style)] aligned on the maximum."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    for label, t, f, style in curves:
        ax.plot(t, f, style, label=label)
    ax.set_xlabel("time from the maximum (us)")
    ax.set_ylabel("dynamic contact force (N)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, path, dpi=130)
    plt.close(fig)
