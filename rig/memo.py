"""Arrays computed once on objects that never change after construction."""
from __future__ import annotations

import numpy as np


def computed_once(owner, name: str, compute) -> np.ndarray:
    """The array ``compute()`` for an object that never changes, computed on the first call
    and kept on it; the array handed out is read-only."""
    memo = owner.__dict__.setdefault("_computed", {})
    if name not in memo:
        value = compute()
        value.setflags(write=False)
        memo[name] = value
    return memo[name]
