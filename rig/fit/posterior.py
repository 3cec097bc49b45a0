"""The posterior of a fit's scene parameters, sampled by MCMC: emcee's affine-invariant
ensemble sampler (Foreman-Mackey et al., PASP 125, 306 (2013)), an optional extra
(``pip install 'sonic-rig[posterior]'``).

The prior is flat within each parameter's bounds; the likelihood is the fit's,

    ln p(theta) = -chi2(theta) / (2 s),   s = max(1, chi2_min / dof),

with the objective's nuisance parameters (trigger offset, gains, delays) profiled out at
each candidate (least squares over them alone: no solve), and s the same scale the fit's
covariance takes when the misfit exceeds the stated uncertainties. Each move of half the
walkers is one batched call of the objective; the candidates are not kept (a chain seldom
comes back to one, and a record's model is megabytes). The chain is kept in
DIR/posterior.h5 after every step (emcee's HDF backend): a run that is stopped and started
again with the same fit, walkers and seed goes on where it stopped. The walkers
start in a ball of 0.1 sd about the least-squares estimate, drawn from ``seed``.
"""
from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import json
import logging
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import optimize

from instruments.files import cause
from rig.errors import Interrupted, RigError
from rig.fit.fitting import FitResult

BURN_FRACTION = 0.5  # the first half of the chain is discarded as burn-in


@dataclass(frozen=True)
class Posterior:
    """Posterior medians and central 68% / 95% intervals (SI units, in the order of
    ``keys``) from walkers x (steps - burn) samples; the mean acceptance fraction; each
    parameter's integrated autocorrelation time in steps (nan where the chain is too short
    to estimate it: fewer than 50 of them) and whether the kept chain is 50 of them long,
    emcee's rule for a trustworthy estimate; the seed of the walkers' start and moves."""

    keys: tuple
    units: tuple
    median: np.ndarray
    ci68: np.ndarray
    ci95: np.ndarray
    walkers: int
    steps: int
    burn: int
    acceptance: float
    autocorr_steps: np.ndarray
    long_enough: bool
    seed: int
    samples: np.ndarray

    def as_dict(self) -> dict:
        return {"parameters": {k: {"median": float(m), "ci68": [float(a), float(b)], "ci95": [float(c), float(d)],
                                   "unit": u}
                               for k, u, m, (a, b), (c, d) in zip(self.keys, self.units, self.median, self.ci68,
                                                                  self.ci95)},
                "walkers": self.walkers, "steps": self.steps, "burn": self.burn,
                "acceptance_fraction": self.acceptance,
                "autocorr_steps": [None if math.isnan(t) else float(t) for t in self.autocorr_steps],
                "long_enough": self.long_enough, "seed": self.seed}


def check(walkers: int | None, n_params: int):
    """RigError unless emcee is installed and ``walkers`` (None: the default) is at least 2
    per parameter, as the affine-invariant moves need."""
    if importlib.util.find_spec("emcee") is None:
        raise RigError("the posterior needs emcee: pip install 'sonic-rig[posterior]'")
    if walkers is not None and walkers < 2 * n_params:
        raise RigError(f"--walkers {walkers}: needs at least 2 per parameter ({2 * n_params} here)")


def profiled_chi2(objective, model, eta0: np.ndarray, bounds) -> float:
    """chi2 of a candidate's model with its nuisance parameters at their best (from eta0)."""
    if eta0.size == 0:
        r = objective.residuals(model, eta0)
        return float(r @ r)
    def residuals(eta: np.ndarray) -> np.ndarray:
        return objective.residuals(model, eta)

    def jacobian(eta: np.ndarray) -> np.ndarray:
        return objective.nuisance_jacobian(model, eta)

    res = optimize.least_squares(residuals, eta0, jac=jacobian, bounds=bounds,
                                 method="trf", xtol=1e-8, ftol=1e-10)
    return float(2.0 * res.cost)


def sample(objective, result: FitResult, folder, walkers: int, steps: int, seed: int = 0,
           progress=None) -> Posterior:
    """Sample the posterior of ``objective``'s parameters about the converged ``result``
    (module doc); the chain in ``folder``/posterior.h5."""
    params = objective.params
    P = len(params)
    check(walkers, P)
    lo = np.array([p.lo for p in params])
    span = np.array([p.hi - p.lo for p in params])
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RigError(f"posterior folder {folder}: cannot create ({exc.strerror})") from None
    _, eta_lo, eta_hi = objective.nuisance_start()
    scale = max(1.0, result.chi2_reduced) if result.dof > 0 else 1.0
    tell = progress or (lambda text: None)
    solved = [0]

    def log_prob(X):
        X = np.atleast_2d(X)
        out = np.full(X.shape[0], -np.inf)
        inside = np.all((X >= 0.0) & (X <= 1.0), axis=1)
        models = objective.evaluate([lo + span * x for x in X[inside]])
        solved[0] += len(models)
        out[inside] = [-0.5 * profiled_chi2(objective, m, result.eta, (eta_lo, eta_hi)) / scale for m in models]
        return np.where(np.isfinite(out), out, -np.inf)

    try:
        backend = _run_chain(objective, (result.estimate - lo) / span, np.maximum(result.std / span, 1e-6), folder,
                             walkers, steps, seed, log_prob, lambda k: tell(f"posterior: step {k}/{steps} "
                                                                             f"({solved[0]} candidates solved)"))
        total = int(backend.iteration)
    except OSError as exc:
        raise RigError(f"{folder / 'posterior.h5'}: {cause(exc)}") from None
    burn = int(BURN_FRACTION * total)
    chain = backend.get_chain(discard=burn, flat=True)
    if chain.shape[0] == 0:
        raise RigError(f"--posterior {steps}: too few steps to sample (at least 2)")
    theta = lo + span * chain
    tau = np.full(P, np.nan)
    if total - burn >= 50:
        quiet = logging.getLogger("emcee").level
        logging.getLogger("emcee").setLevel(logging.ERROR)  # its "chain too short" is said by long_enough
        try:
            tau = backend.get_autocorr_time(discard=burn, quiet=True)
        finally:
            logging.getLogger("emcee").setLevel(quiet)
    long_enough = bool(np.all(np.isfinite(tau)) and total - burn >= 50 * np.max(tau))
    q = np.percentile(theta, [2.5, 16, 50, 84, 97.5], axis=0)
    return Posterior(tuple(p.key for p in params), tuple(p.unit for p in params), q[2], q[[1, 3]].T, q[[0, 4]].T,
                     walkers, total, burn, float(np.mean(backend.accepted / max(total, 1))), tau, long_enough,
                     seed, theta)


def _run_chain(objective, x_hat, sd, folder, walkers, steps, seed, log_prob, tell):
    """emcee's sampler on posterior.h5: a new chain from a ball of 0.1 sd about x_hat (the
    normalised estimate), or the stored one continued to ``steps``; tell(k) every 10 steps.
    Returns the backend."""
    import emcee

    P = len(objective.params)
    tag = hashlib.sha256(json.dumps([objective.spec(), walkers, seed], sort_keys=True,
                                    default=float).encode()).hexdigest()[:16]
    backend = _backend(str(folder / "posterior.h5"), f"chain_{tag}")
    done = int(backend.iteration) if backend.initialized else 0
    sampler = emcee.EnsembleSampler(walkers, P, log_prob, vectorize=True, backend=backend)
    if done == 0:
        backend.reset(walkers, P)
        rng = np.random.default_rng(seed)
        start = np.clip(x_hat + 0.1 * sd * rng.standard_normal((walkers, P)), 0.0, 1.0)
        sampler.random_state = np.random.RandomState(seed).get_state()
    else:
        start = backend.get_last_sample()  # the walkers and the generator's state where they stopped
    with _ctrl_c_between_steps() as asked:
        for k, _ in enumerate(sampler.sample(start, iterations=max(0, steps - done)), start=done + 1):
            if k % 10 == 0 or k == steps:
                tell(k)
            if asked():
                raise Interrupted(f"interrupted: {k} of {steps} steps of the chain are kept in "
                                  f"{folder / 'posterior.h5'}; run the same command again to continue it")
    return backend


def _backend(path: str, name: str):
    """emcee's HDF backend on ``path``, each change of which (a step, the chain's storage
    grown) is made in memory and the file then replaced whole (instruments.files): HDF5
    writing in place on a full disk had crashed the process. A file there that cannot be
    read (cut short by an older version, damaged) is dropped with a note on stderr, and
    the chain starts again."""
    import emcee
    import h5py

    from instruments.files import atomic_write, hdf5_in_memory

    try:
        if Path(path).exists():
            h5py.File(path, "r").close()
    except Exception as exc:  # noqa: BLE001 - any unreadable file
        why = " ".join(f"{type(exc).__name__} {exc}".split())
        print(f"{path}: unreadable ({why}); dropped, the chain starts again", file=sys.stderr, flush=True)
        Path(path).unlink()

    class WholeFileBackend(emcee.backends.HDFBackend):
        def open(self, mode="r"):
            return super().open(mode) if mode == "r" else self._changed()

        @contextlib.contextmanager
        def _changed(self):
            stored = Path(self.filename)
            with hdf5_in_memory(stored.read_bytes() if stored.exists() else None) as f:
                yield f
                f.flush()
                image = f.id.get_file_image()
            atomic_write(stored, lambda tmp: Path(tmp).write_bytes(image))

    return WholeFileBackend(path, name=name)


@contextlib.contextmanager
def _ctrl_c_between_steps():
    """Ctrl-C (SIGINT) ends the sampling after the step under way, whose walkers are then
    stored: a KeyboardInterrupt raised inside emcee's call of the likelihood made emcee
    print its own traceback. Yields a function: whether Ctrl-C was pressed. Outside the
    main thread (no signal handler there) Ctrl-C is left as it is."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return
    pressed = []
    before = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        yield lambda: bool(pressed)
    finally:
        signal.signal(signal.SIGINT, before)


def draw(path: Path, post: Posterior):
    """posterior.png: each parameter's histogram, and each pair's samples."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rig.viz.figures import save

    P = len(post.keys)
    fig, axes = plt.subplots(P, P, figsize=(2.4 * P + 1, 2.4 * P + 1), squeeze=False)
    for i in range(P):
        for j in range(P):
            ax = axes[i, j]
            if j > i:
                ax.axis("off")
            elif i == j:
                ax.hist(post.samples[:, i], bins=30, color="0.6")
                for v in (*post.ci95[i], post.median[i]):
                    ax.axvline(v, color="C3", lw=0.8)
            else:
                ax.plot(post.samples[:, j], post.samples[:, i], ".", ms=1, alpha=0.4, color="C0")
            if i == P - 1:
                ax.set_xlabel(f"{post.keys[j]} ({post.units[j]})", fontsize=7)
            if j == 0 and i > 0:
                ax.set_ylabel(f"{post.keys[i]} ({post.units[i]})", fontsize=7)
            ax.tick_params(labelsize=6)
    fig.suptitle(f"posterior: {post.walkers} walkers x {post.steps} steps (first {post.burn} discarded), "
                 f"acceptance {post.acceptance:.2f}", fontsize=8)
    fig.tight_layout()
    save(fig, path, dpi=120)
    plt.close(fig)
