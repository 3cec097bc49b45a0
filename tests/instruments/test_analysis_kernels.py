"""The compiled helpers of the analysis give what scipy and numpy give."""
import numpy as np
import pytest
from scipy.signal import find_peaks, peak_prominences

from instruments._kernels.parabola import parabola
from instruments._kernels.prominence import prominence_bases


def _signals():
    rng = np.random.default_rng(7)
    for k in range(240):
        n = int(rng.integers(3, 600))
        if k % 3 == 0:
            yield rng.integers(0, 6, n).astype(float)  # 8-bit-like plateaus and ties
        elif k % 3 == 1:
            yield np.round(rng.standard_normal(n).cumsum())
        else:
            yield rng.standard_normal(n)


def test_prominence_bases_are_scipys_bit_for_bit():
    checked = 0
    for x in _signals():
        peaks = find_peaks(x)[0]
        if not peaks.size:
            continue
        prom, left, right = peak_prominences(x, peaks)
        lb, rb = prominence_bases(x)
        assert np.array_equal(lb[peaks], left) and np.array_equal(rb[peaks], right)
        assert np.array_equal(x[peaks] - np.maximum(x[lb[peaks]], x[rb[peaks]]), prom)
        checked += peaks.size
    assert checked > 5000


def test_parabola_is_the_least_squares_fit():
    rng = np.random.default_rng(3)
    for _ in range(500):
        n = int(rng.integers(3, 40))
        x = np.arange(n, dtype=float) - rng.integers(0, n)
        y = 2.0 - 0.3 * x**2 + 0.1 * x + rng.standard_normal(n)
        scale = np.abs(y).max()
        ref = np.polyfit(x, y, 2)
        got = np.array(parabola(x, y))
        # the normal equations in sample units lose at most a few digits against polyfit's QR
        assert np.allclose(got * np.array([n * n, n, 1.0]), ref * np.array([n * n, n, 1.0]), rtol=0, atol=1e-9 * scale)
    assert all(np.isnan(parabola(np.array([0.0, 0.0, 1.0]), np.array([1.0, 2.0, 3.0]))))


@pytest.mark.parametrize("n", [3, 7])
def test_parabola_is_exact_on_a_parabola(n):
    x = np.arange(n, dtype=float) - n // 2
    a, b, c = parabola(x, -1.5 * x**2 + 0.25 * x + 4.0)
    assert (a, b, c) == pytest.approx((-1.5, 0.25, 4.0), rel=1e-13, abs=1e-13)
