"""Where a pulse falls to a level on either side of its maximum (numba)."""
from numerics.jit import jit


@jit
def level_bracket(f, i, level):
    """(left, right): the nearest samples at or below ``level`` at or before sample i, and
    at or after it; -1 where the signal never gets there. Scans outward from i only as far
    as it must."""
    left = i
    while left >= 0 and not f[left] <= level:
        left -= 1
    right = i
    while right < f.shape[0] and not f[right] <= level:
        right += 1
    return left, (right if right < f.shape[0] else -1)
