"""Uncertain inputs: distributions for scene quantities, by dotted key.

    normal(MEAN, SD)                 truncnormal(MEAN, SD, LO, HI)
    uniform(LO, HI)                  lognormal(MEAN, SD)   (of the quantity itself)

Each argument is a quantity with a unit where the key has one ("normal(0.89 m/s, 0.01 m/s)").
Besides every numeric scene key, the Monte Carlo knows a few per-shot inputs the scene
draws internally otherwise: ``chain.bead_mass`` (each plain bead its own draw),
``gauges.NAME.gain`` (true/nominal sensitivity) and ``gauges.NAME.misalignment`` (m).
A distribution that can draw a value outside the key's physical range (a negative mass,
a Poisson ratio of 0.5) is refused: truncate it or use a lognormal.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from scipy import stats

from rig.errors import invalid
from rig.experiment.scene import schema_node, unknown_key
from rig.units import check_digits, number, quantity

EXTRA_KEYS = {"chain.bead_mass": "kg", "chain.youngs_modulus": "Pa", "chain.poisson_ratio": float}
GAUGE_KEYS = {"gain": float, "misalignment": "m"}
_BEAD_MASS = "each plain bead's mass: chain.bead_mass a draw per bead, chain.mass one draw for all"
ONE_QUANTITY = {"chain.mass": {"chain.bead_mass": _BEAD_MASS}, "chain.bead_mass": {"chain.mass": _BEAD_MASS}}
"""Keys that name one quantity two ways: a study varies one of them."""
_SIGNED = ("offset", "position", "misalignment", "level")
_NON_NEGATIVE = ("noise", "noise_floor", "calibration_error", "gap", "misalignment_sd")
_SPEC = re.compile(r"^\s*(normal|truncnormal|uniform|lognormal)\s*\((.*)\)\s*$", re.IGNORECASE)
_ARITY = {"normal": 2, "truncnormal": 4, "uniform": 2, "lognormal": 2}


def key_unit(key: str):
    """The key's SI unit (a string), float for a plain number; RigError if unknown."""
    if key in EXTRA_KEYS:
        return EXTRA_KEYS[key]
    parts = key.split(".")
    if len(parts) == 3 and parts[0] == "gauges" and parts[2] in GAUGE_KEYS:
        return GAUGE_KEYS[parts[2]]
    try:
        node = schema_node(key)
    except KeyError:
        raise invalid("--vary", key, unknown_key(key, tuple(EXTRA_KEYS))) from None
    if node is int:
        raise invalid("--vary", key, "a whole-number key (a count or an index) cannot take a continuous "
                                     "distribution; run one study per value, or rig sweep")
    if node is not float and not isinstance(node, str):
        raise invalid("--vary", key, "only numeric keys can be uncertain")
    return float if node is float else node


def key_range(key: str):
    """(lo, hi, lo_open) of the physically allowed values of a key."""
    last = key.split(".")[-1]
    if last == "poisson_ratio":
        return -1.0, 0.5, True
    if last == "gain":
        return 0.0, math.inf, True
    if any(last.endswith(s) for s in _SIGNED):
        return -math.inf, math.inf, False
    if last in _NON_NEGATIVE:
        return 0.0, math.inf, False
    if key_unit(key) is float and last not in ("accuracy",):
        return -math.inf, math.inf, False
    return 0.0, math.inf, True


@dataclass(frozen=True)
class Distribution:
    key: str
    kind: str
    params: tuple  # SI

    @classmethod
    def parse(cls, key: str, text: str) -> Distribution:
        m = _SPEC.match(text)
        if not m:
            raise invalid(f"--vary {key}", text, "normal(MEAN, SD), truncnormal(MEAN, SD, LO, HI), "
                                                   "uniform(LO, HI) or lognormal(MEAN, SD)")
        kind = m.group(1).lower()
        args = [x.strip() for x in m.group(2).split(",")]
        if len(args) != _ARITY[kind] or not all(args):
            if len(re.split(r",\s+", m.group(2))) == _ARITY[kind]:  # "normal(0,89 m/s, 0,01 m/s)"
                check_digits(text, f"--vary {key}")
            raise invalid(f"--vary {key}", text, f"{kind} takes {_ARITY[kind]} arguments, none of them empty")
        unit = key_unit(key)
        vals = tuple(_value(a, unit, key) for a in args)
        d = cls(key, kind, vals)
        d._check()
        return d

    def _check(self):
        k, p = self.kind, self.params
        field = f"--vary {self.key}"
        lo, hi, lo_open = key_range(self.key)
        if k in ("normal", "truncnormal", "lognormal") and not p[1] > 0:
            raise invalid(field, self.text(), "the standard deviation must be > 0")
        if k in ("uniform",) and not p[0] < p[1]:
            raise invalid(field, self.text(), "needs LO < HI")
        if k == "truncnormal" and not p[2] < p[3]:
            raise invalid(field, self.text(), "needs LO < HI")
        if k == "lognormal" and not p[0] > 0:
            raise invalid(field, self.text(), "a lognormal needs MEAN > 0")
        if k == "lognormal" and not p[1] / p[0] < 1e100:  # its log's variance, log(1 + (SD/MEAN)^2), must be finite
            raise invalid(field, self.text(), "a lognormal needs SD < 1e100 MEAN")
        support = {"normal": (p[0] - 8 * p[1], p[0] + 8 * p[1]) if k == "normal" else None,
                   "truncnormal": (p[2], p[3]) if k == "truncnormal" else None,
                   "uniform": (p[0], p[1]) if k == "uniform" else None,
                   "lognormal": (0.0, math.inf)}[k]
        assert support is not None, "k is one of the four kinds"
        below = support[0] <= lo if lo_open else support[0] < lo
        above = support[1] >= hi if math.isfinite(hi) else False
        if k == "lognormal" and lo >= 0:
            below = False
        if below or above:
            unit = key_unit(self.key)
            allowed = f"{'(' if lo_open else '['}{lo:g}, {hi:g})" + ("" if unit is float else f" {unit}")
            remedy = ("truncate it (truncnormal) or use a lognormal" if k in ("normal", "lognormal")
                      else "keep LO and HI inside it")
            raise invalid(field, self.text(), f"can draw values outside the allowed range {allowed} "
                                              f"(the values in SI units); {remedy}")

    def text(self) -> str:
        return f"{self.kind}({', '.join(f'{x:g}' for x in self.params)})"

    @property
    def standard(self) -> str:
        """The standard draws a value is made of: "normal" (standard normals) or "uniform"
        (in [0, 1))."""
        return "uniform" if self.kind in ("uniform", "truncnormal") else "normal"

    def from_standard(self, z: np.ndarray) -> np.ndarray:
        """Values from standard draws z (``standard``), with the operations numpy's
        Generator.normal, uniform and lognormal apply to theirs (loc + scale z,
        low + (high - low) u, exp(mu + sigma z) by the C library's exp), so the values are
        the ones those methods draw from the same stream; truncnormal: its ppf at u."""
        k, p = self.kind, self.params
        if k == "normal":
            return p[0] + p[1] * z
        if k == "uniform":
            return p[0] + (p[1] - p[0]) * z
        if k == "lognormal":
            mu, sigma = self._log_params()
            return np.array([math.exp(mu + sigma * v) for v in np.ravel(z)]).reshape(np.shape(z))
        a, b = (p[2] - p[0]) / p[1], (p[3] - p[0]) / p[1]
        return stats.truncnorm.ppf(z, a, b, loc=p[0], scale=p[1])

    def _log_params(self) -> tuple:
        """A lognormal's (mu, sigma): the mean and sd of its log, from its MEAN and SD."""
        mean, sd = self.params
        s2 = math.log1p((sd / mean) ** 2)
        return math.log(mean) - 0.5 * s2, math.sqrt(s2)

    def salib(self):
        """(dist name, bounds) in SALib's terms, for Sobol sampling."""
        k, p = self.kind, self.params
        if k == "uniform":
            return "unif", [p[0], p[1]]
        if k == "normal":
            return "norm", [p[0], p[1]]
        if k == "lognormal":
            return "lognorm", list(self._log_params())
        return "truncnorm", [p[2], p[3], p[0], p[1]]


def _value(text: str, unit, key):
    if unit is float:
        return number(text, f"--vary {key}")
    return quantity(text, unit, f"--vary {key}")


def parse_vary(items) -> list:
    """["KEY=DIST", ...] -> [Distribution]; one distribution per key."""
    allowed = 'a list of KEY=DIST texts, e.g. ["striker.velocity=normal(0.89 m/s, 0.01 m/s)"]'
    if isinstance(items, str):
        raise invalid("--vary", items, allowed)
    try:
        items = list(items)
    except TypeError:
        raise invalid("--vary", items, allowed) from None
    if not all(isinstance(item, str) for item in items):
        raise invalid("--vary", items, allowed)
    out, seen = [], set()
    for item in items:
        if "=" not in item:
            raise invalid("--vary", item, 'expected KEY=DIST, e.g. striker.velocity="normal(0.89 m/s, 0.01 m/s)"')
        key, spec = (s.strip() for s in item.split("=", 1))
        if key in seen:
            raise invalid("--vary", key, "given twice")
        if key.split(".")[0] == "solver":
            raise invalid("--vary", key, "a key of the scene's parts or gauges: every shot of a study takes the "
                                         "study's own solver settings (--accuracy, --window)")
        alias = next((a for a in ONE_QUANTITY.get(key, ()) if a in seen), None)
        if alias is not None:
            raise invalid("--vary", key, f"names the quantity {alias} names too ({ONE_QUANTITY[key][alias]}): the "
                                         f"one varied later would override the other's draws; vary one of them")
        seen.add(key)
        out.append(Distribution.parse(key, spec))
    return out
