"""The bounds the model families of `rig reproduce daraio2006 --fitted` are fitted within
(rig.study.fitted_families), each with where it comes from: published measurements of PTFE
and of its contacts, or, where nothing is published, the reason for the range. fitted.json
repeats each family's bounds with their sources (``sources``).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Bound:
    """A fitted key's bounds, ``text`` as a fit reads them (KEY=LO:HI, rig.fit.parameters),
    and ``source``: where they come from."""

    text: str
    source: str

    @property
    def key(self) -> str:
        return self.text.split("=", 1)[0]


E = Bound("chain.youngs_modulus=0.4 GPa:3 GPa",
          "PTFE's Young's modulus. Lower: the quasi-static value, about 0.4-0.55 GPa in tension (ASTM D638) and "
          "0.48 GPa in compression (ASTM D695) in PTFE resin data sheets. Upper: twice the dynamic 1.46 GPa "
          "Daraio et al. (Phys. Rev. E 73, 026610, 2006) used for these beads, room for a polymer's modulus "
          "rising with the strain rate (Siviour & Jordan, J. Dyn. Behav. Mater. 2, 15, 2016) at the contacts' "
          "1e3-1e4 /s.")
EXPONENT = Bound("chain.contact_exponent=1.05:2.6",
                 "The exponent of an elastic power-law contact F = A delta^n: above 1 the chain is strongly "
                 "nonlinear (Nesterenko, Dynamics of Heterogeneous Materials, Springer, 2001); 1.5 a sphere (Hertz), "
                 "2 a cone (Sneddon, Int. J. Eng. Sci. 3, 47, 1965). No exponent of PTFE bead contacts is "
                 "published; the upper bound leaves the data room beyond a cone's.")
DASHPOT = Bound("chain.contact_damping=0.001 kg/s:3 kg/s",
                "A linear dashpot in each contact; no value for PTFE contacts is published. Upper: the critical "
                "damping 2 sqrt(k m / 2) of a PTFE bead pair linearised at its static load under gravity (k = "
                "dF/d delta at 0.017 N, E 0.4-1.5 GPa: 2.2-3.4 kg/s; 5-9 kg/s at the pulses' 2-6 N): above the "
                "critical viscosity a chain's front is a monotonic shock, not the oscillating train of Fig. 3 "
                "(Herbold & Nesterenko, Phys. Rev. E 75, 021304, 2007).")
YIELD_PRESSURE = Bound("chain.yield_pressure=14 MPa:120 MPa",
                       "The limiting contact pressure p_y of the elastic-plastic law (Thornton, J. Appl. Mech. 64, "
                       "383, 1997). PTFE yields in compression at about 9-12 MPa at quasi-static rates and room "
                       "temperature, rising with the strain rate as rate^m, m 0.05-0.1 (Rae & Dattelbaum, Polymer 45, "
                       "7615, 2004): 2-4 times that at the contacts' 1e3 /s, 20-40 MPa. A Hertz contact first yields "
                       "at a centre pressure of 1.6 times the yield stress and is fully plastic at a mean pressure of "
                       "about 3 times it (Johnson, Contact Mechanics, Cambridge University Press, 1985, ch. 6): "
                       "1.6 x 9 MPa to 3 x 40 MPa.")
RATE = Bound("chain.yield_rate_exponent=0:0.15",
             "m in p_y ~ rate^m above the law's reference rate: PTFE's yield stress rises as rate^0.05-0.1 (Rae & "
             "Dattelbaum, Polymer 45, 7615, 2004); 0 is a rate-independent yield, 0.15 leaves room above.")
RATIO = Bound("chain.static_yield_ratio=0.1:1",
              "The static hold's yield pressure over the shot's: with PTFE's yield rising as rate^m, m 0.05-0.1 (Rae "
              "& Dattelbaum, 2004), the 7-9 decades between a 600 s hold's creep (about 1e-5 /s) and a shot's 1e3-1e4 "
              "/s give 10^-0.9 to 10^-0.35, 0.13-0.45; 1 is a yield that does not depend on the rate.")
GAMMA = Bound("chain.dashpot_gamma=0.001:3",
              "A power-law dashpot's gamma (N (s/m)^alpha, SI; Carretero-Gonzalez et al., Phys. Rev. Lett. 102, "
              "024102, 2009): at alpha = 1 the linear dashpot, whose bounds it takes.")
ALPHA = Bound("chain.dashpot_exponent=0.5:2",
              "A power-law dashpot's exponent alpha (Carretero-Gonzalez et al., 2009): 1 a linear dashpot; no "
              "exponent of PTFE contacts is published, the bounds allow a factor 2 either way.")
FRICTION = Bound("holder.friction=0 N:0.1 N",
                 "Coulomb friction of each bead on the holder's wall: PTFE slides on PTFE at a friction coefficient "
                 "of about 0.05-0.1 at low speeds (Makinson & Tabor, Proc. R. Soc. A 281, 49, 1964), but the force a "
                 "bead presses the tube's wall with is not "
                 "published; 0.1 N, 80 times a bead's weight, leaves the fit room to say what the data ask for.")

SOURCES = {b.key: b.source for b in (E, EXPONENT, DASHPOT, YIELD_PRESSURE, RATE, RATIO, GAMMA, ALPHA, FRICTION)}
"""{fitted key: where its bounds come from}."""
