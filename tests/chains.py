"""Shared chain builders for the tests (small chains keep the suite fast). Plain Python, no
pytest: tests/compile_once.py builds its chains from them before pytest is installed."""
from rig import Bead, Chain, MagneticBead, SaveAt, Striker, Wall

STEEL = dict(material="steel316", diameter="4.76 mm", mass="0.4501 g")
PTFE = dict(material="ptfe", diameter="4.76 mm", mass="0.1226 g")


def steel_sonic_vacuum(n=60, velocity="0.44 m/s", wall=False):
    """Horizontal steel chain (no gravity, no precompression) struck by one bead mass."""
    return Chain([Bead(**STEEL)] * n, striker=Striker("steel316", "0.4501 g", velocity),
                 wall=Wall() if wall else None, gravity=0)


def ptfe_rig(n=52, top_force=2.38, striker=True, velocity="0.89 m/s"):
    """The published PTFE set-up: magnetic bead on n PTFE beads, wall, gravity."""
    beads = [MagneticBead()] + [Bead(**PTFE)] * n
    st = Striker("alumina", "0.47 g", velocity) if striker else None
    return Chain(beads, striker=st, wall=Wall(), top_force=top_force)


def record_contacts(chain, *contacts, **kw):
    return SaveAt({f"c{k}": chain.contact_probe(k) for k in contacts}, **kw)
