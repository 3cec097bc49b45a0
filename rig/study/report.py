"""The study's report: JCGM 101 (GUM Supplement 1) summaries and figures (Sobol indices:
rig/study/sobol.py)."""
from __future__ import annotations

import math

import numpy as np


def jcgm101(y: np.ndarray, n_dig: int = 2, blocks: int = 10) -> dict:
    """Estimate (mean), standard uncertainty, probabilistically symmetric 95% coverage
    interval and the adaptive stabilisation check of JCGM 101:2008 section 7.9: the results
    are split into ``blocks`` equal runs; the result has stabilised when twice the standard
    deviation of each run-wise quantity is within the numerical tolerance delta, half a
    unit of the last of ``n_dig`` significant digits of u(y)."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    n = y.size
    if n < 2:
        return {"estimate": None, "std": None, "ci95": [None, None], "trials": int(n),
                "converged": False, "tolerance": None}
    est, u = float(np.mean(y)), float(np.std(y, ddof=1))
    lo, hi = (float(q) for q in np.quantile(y, [0.025, 0.975]))
    out = {"estimate": est, "std": u, "ci95": [lo, hi], "trials": int(n)}
    if u == 0:
        return {**out, "converged": True, "tolerance": 0.0}
    delta = 0.5 * 10 ** (math.floor(math.log10(u)) - (n_dig - 1))
    m = n // blocks
    if m < 2:
        return {**out, "converged": False, "tolerance": delta}
    runs = y[: m * blocks].reshape(blocks, m)
    stats = [runs.mean(1), runs.std(1, ddof=1), np.quantile(runs, 0.025, axis=1), np.quantile(runs, 0.975, axis=1)]
    worst = max(float(np.std(s, ddof=1) / math.sqrt(blocks)) for s in stats)
    return {**out, "converged": bool(2 * worst <= delta), "tolerance": delta,
            "stabilisation": 2 * worst}


def failures(codes: np.ndarray) -> dict:
    """The failed shots: how many, their share of all shots and how many per reason
    (``codes``: each shot's "failure" output, a Failure code, Failure.NONE for none)."""
    from rig.study.mc_spec import Failure

    codes = np.asarray(codes, dtype=int)
    bad = codes[codes != Failure.NONE]
    kinds, counts = np.unique(bad, return_counts=True)
    return {"count": int(bad.size), "share": float(bad.size / codes.size) if codes.size else 0.0,
            "reasons": {Failure(k).message: int(n) for k, n in zip(kinds, counts)}}


def figures(folder, results, keys, theory_curve=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rig.viz.figures import save

    out = results.outputs
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, key, label in ((axes[0], "speed_m_per_s", "measured speed V_s (m/s)"),
                           (axes[1], "amplitude_N", "measured amplitude F_d (N)")):
        y = out[key][np.isfinite(out[key])]
        ax.hist(y, bins=max(10, int(np.sqrt(y.size))), color="C0", alpha=0.8, label=f"{y.size} shots")
        t = out["truth_" + key][np.isfinite(out["truth_" + key])]
        if t.size:
            ax.axvline(float(np.mean(t)), color="k", ls="--", label="truth (mean)")
        ax.set_xlabel(label)
        ax.set_ylabel("shots")
        ax.legend(fontsize=8)
    fig.tight_layout()
    save(fig, folder / "histograms.png", dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(5.6, 4.2))
    ax.plot(out["amplitude_N"], out["speed_m_per_s"], "C0.", ms=3, alpha=0.5, label="virtual shots (measured)")
    ax.plot(out["truth_amplitude_N"], out["truth_speed_m_per_s"], "k.", ms=3, label="truth")
    if theory_curve is not None:
        F, V, label = theory_curve
        ax.plot(F, V, "C3-", label=label)
    ax.set_xlabel("F_d (N)")
    ax.set_ylabel("V_s (m/s)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, folder / "speed_vs_amplitude.png", dpi=120)
    plt.close(fig)
