"""rig bench models: every optional model measured, and each one's "off" settings are
plain Hertz bit for bit (what "costs nothing when off" rests on)."""
from rig.bench import models


def test_models_bench_off_rows_are_hertz_and_dissipation_is_booked(monkeypatch):
    # the per-step figures (nothing is asserted of them but their place in the table) on the
    # bench's 1000-bead chain, every model's solve as the bench runs it, over a tenth of its steps
    monkeypatch.setattr(models, "FIXED_STEPS", 200)
    r = models.run(quick=True)
    rows = {x["model"]: x for x in r["rows"]}
    assert set(rows) == set(models.ON) | set(models.OFF)
    for name in models.OFF:
        assert rows[name]["same_bits_as_hertz"] is True, name
        assert rows[name]["dt_s"] == rows["hertz"]["dt_s"], name
    for name in ("Kuwabara-Kono 2 us", "dashpot 0.5 kg/s", "holder drag", "holder friction", "all together"):
        assert rows[name]["dissipated_share"] > 0.01, name
    for name in ("hertz", "power law n=1.75", "compliant wall", "gauge mass"):
        assert rows[name]["dissipated_share"] == 0.0, name
    for x in r["rows"]:  # every controlled solve kept its contract
        assert x["estimate"] <= models.ACCURACY, x["model"]
    text = models.table(r)
    assert all(name in text for name in rows)
