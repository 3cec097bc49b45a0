"""Shared chain builders for the tests (small chains keep the suite fast)."""
import pytest

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


@pytest.fixture
def sonic_vacuum():
    return steel_sonic_vacuum


@pytest.fixture
def realdata():
    """The real Tektronix files in ../shared/realdata (beside the checkout). CI must have
    them; elsewhere their absence skips the test with the reason."""
    import os
    from pathlib import Path

    here = Path(__file__).resolve().parents[1]
    for base in (here.parent / "shared" / "realdata", here / "shared" / "realdata"):
        if (base / "tek_16bit_dpo.isf").is_file():
            return base
    if os.environ.get("CI"):
        pytest.fail("../shared/realdata is missing: the real scope files are required in CI")
    pytest.skip("real scope files not found beside the checkout (../shared/realdata)")
