"""The wings' public names: every name that instruments, instruments.analysis and
instruments.devices say they hold resolves to the object of its defining module, an
unknown name is refused by name, and naming them loads nothing: importing a light module
of a wing (the analysis' report, the errors) loads no numba and no other room."""
import importlib
import subprocess
import sys

import pytest

import instruments
from instruments import analysis, devices


@pytest.mark.parametrize("package, table", [(analysis, analysis.PUBLIC), (devices, devices.PUBLIC)])
def test_every_public_name_is_its_modules_object(package, table):
    assert sorted(package.__all__) == sorted(n for names in table.values() for n in names)
    for module, names in table.items():
        defining = importlib.import_module(f"{package.__name__}.{module}")
        for name in names:
            assert getattr(package, name) is getattr(defining, name), f"{package.__name__}.{name}"
            assert getattr(instruments, name) is getattr(defining, name), f"instruments.{name}"


def test_the_package_names_both_wings_and_nothing_else():
    assert sorted(instruments.__all__) == sorted(analysis.__all__ + devices.__all__)
    with pytest.raises(AttributeError, match="'instruments.analysis' has no attribute 'remove_baseline'"):
        analysis.remove_baseline  # noqa: B018 (removed: it had no caller)


def test_a_light_module_of_a_wing_loads_no_compiled_code():
    heavy = ("instruments.devices.", "instruments.analysis.pipeline", "instruments._kernels", "numba", "numerics")
    code = ("import sys, instruments.analysis.report, instruments.analysis.plausibility, instruments.errors\n"
            f"print(' '.join(sorted(m for m in sys.modules if m.startswith({heavy!r}))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == []
