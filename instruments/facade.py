"""A wing's public names, loaded on first use (PEP 562): importing one module of a wing
(its report, its plausibility limits) loads none of the others and no compiled loop."""
from __future__ import annotations

import importlib


def lazy_names(package: str, public: dict) -> tuple:
    """(``__getattr__``, ``__all__``) of ``package`` whose ``public`` names ({module: names},
    modules relative to the package) load from their module when first asked for."""
    where = {name: f"{package}.{module}" for module, names in public.items() for name in names}

    def __getattr__(name: str):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(where[name]), name)

    return __getattr__, sorted(where)
