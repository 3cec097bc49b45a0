"""One parameter set fitted to several objectives at once (e.g. Table 1's points and Fig. 3's
observations): the residuals of the parts are concatenated, each in its own units of
standard deviation, so chi2 is the sum of the parts' chi2 and every datum weighs by its own
uncertainty. The parts' nuisance parameters are kept, each part's after the previous'.

Each part solves its candidates in one batched call (rig.fit.evaluate); the parts are not
merged into one call because their shots differ in duration (a leading window against whole
records) and in their pilot's step, which the batched kernel would split again.
"""
from __future__ import annotations

from itertools import pairwise

import numpy as np

from rig.errors import invalid


class JointObjective:
    """The objectives ``parts`` (each with the same fitted parameters) as one (module doc);
    ``start``: where the fit starts (SI, in the parameters' order; None: the first part's
    start, the scene's values)."""

    def __init__(self, parts, start=None):
        self.parts = tuple(parts)
        if not self.parts:
            raise invalid("joint fit", "no objective", "at least one objective to fit")
        self.params = self.parts[0].params
        for p in self.parts[1:]:
            if p.params != self.params:
                raise invalid("joint fit", [q.key for q in p.params],
                              f"the same fitted parameters in every part ({[q.key for q in self.params]})")
        self._start = None if start is None else np.asarray(start, dtype=float)
        if self._start is not None and self._start.shape != (len(self.params),):
            raise invalid("joint fit start", self._start.tolist(), f"{len(self.params)} values, one per parameter")
        self.central_differences = any(p.central_differences for p in self.parts)
        sizes = [p.n_data for p in self.parts]
        ends = np.cumsum([0] + sizes)
        self.slices = tuple(slice(int(a), int(b)) for a, b in pairwise(ends))
        """The rows of each part in the joint residuals."""
        eta_sizes = [p.nuisance_start()[0].size for p in self.parts]
        eta_ends = np.cumsum([0] + eta_sizes)
        self.eta_slices = tuple(slice(int(a), int(b)) for a, b in pairwise(eta_ends))

    def spec(self) -> dict:
        return {"kind": "joint", "parts": [p.spec() for p in self.parts], "start": self.start().tolist()}

    def numerics(self, theta) -> dict:
        """Each part's numerics (rig.fit.evaluate.numerics); within_accuracy: all of them."""
        parts = [p.numerics(theta) for p in self.parts]
        return {"parts": parts, "within_accuracy": all(n["within_accuracy"] for n in parts)}

    def start(self) -> np.ndarray:
        return self.parts[0].start() if self._start is None else self._start

    @property
    def n_data(self) -> int:
        return sum(p.n_data for p in self.parts)

    @property
    def data_name(self) -> str:
        return " and ".join(p.data_name for p in self.parts)

    def evaluate(self, thetas: list) -> list:
        """Each candidate's model: the tuple of the parts' models."""
        per_part = [p.evaluate(thetas) for p in self.parts]
        return [tuple(models) for models in zip(*per_part)]

    def pack(self, model) -> dict:
        return {f"{i}:{k}": v for i, (p, m) in enumerate(zip(self.parts, model)) for k, v in p.pack(m).items()}

    def unpack(self, z: dict):
        return tuple(p.unpack({k.split(":", 1)[1]: v for k, v in z.items() if k.split(":", 1)[0] == str(i)})
                     for i, p in enumerate(self.parts))

    def residuals(self, model, eta) -> np.ndarray:
        return np.concatenate([p.residuals(m, eta[s]) for p, m, s in zip(self.parts, model, self.eta_slices)])

    def relative_residuals(self, model) -> np.ndarray:
        """Each part's model / measured - 1, concatenated (nan where a part has none)."""
        return np.concatenate([p.relative_residuals(m) for p, m in zip(self.parts, model)])

    def relative_rms(self, model, eta) -> float:
        """RMS of the relative residuals of all parts (those without one left out)."""
        rel = self.relative_residuals(model)
        rel = rel[np.isfinite(rel)]
        return float(np.sqrt(np.mean(rel ** 2))) if rel.size else float("nan")

    def rows(self, model, residuals) -> list:
        """The rows of the parts that have them (rig.fit.observations), for residuals.csv."""
        return [row for p, m, s in zip(self.parts, model, self.slices) if hasattr(p, "rows")
                for row in p.rows(m, residuals[s])]

    def figures(self, model, residuals) -> list:
        """The figures of the parts that have them (rig.fit.observations), for fit.json."""
        return [f for p, m, s in zip(self.parts, model, self.slices) if hasattr(p, "figures")
                for f in p.figures(m, residuals[s])]

    def nuisance_start(self):
        starts = [p.nuisance_start() for p in self.parts]
        return tuple(np.concatenate([s[i] for s in starts]) for i in range(3))

    def nuisance_jacobian(self, model, eta):
        J = np.zeros((self.n_data, eta.size))
        for p, m, s, e in zip(self.parts, model, self.slices, self.eta_slices):
            J[s, e] = p.nuisance_jacobian(m, eta[e])
        return J

    def nuisance_report(self, eta) -> dict:
        out = {}
        for p, e in zip(self.parts, self.eta_slices):
            out.update(p.nuisance_report(eta[e]))
        return out
