"""The compiled helpers of the instruments and the analysis give what scipy and numpy give,
to the last bit where they replace a library call (compared as raw 64-bit patterns)."""
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.signal import find_peaks, lfilter, peak_prominences, peak_widths

from instruments._kernels.filters import one_pole, undo_highpass
from instruments.analysis._kernels.parabola import parabola
from instruments.analysis._kernels.peaks import local_maxima, thin_by_distance, widths_at
from instruments.analysis._kernels.prominence import prominence_bases, prominent
from instruments.analysis._kernels.select import first_largest, kept, largest, left_index, stable_order, taken
from instruments.devices._kernels.quantiser import quantise
from instruments.devices._kernels.resample import at_positions


def _same_bits(a, b):
    return a.shape == b.shape and np.array_equal(np.asarray(a, float).view(np.int64),
                                                 np.asarray(b, float).view(np.int64))


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


@pytest.mark.parametrize("with_floor", [False, True])
def test_prominence_bases_are_scipys_bit_for_bit(with_floor):
    # with a floor (find_peaks' height rule) only the samples at or above it have bases
    rng = np.random.default_rng(11)
    checked = 0
    for x in _signals():
        floor = float(np.quantile(x, rng.uniform(0, 1))) if with_floor else -np.inf
        peaks = find_peaks(x, height=floor)[0]
        if not peaks.size:
            continue
        prom, left, right = peak_prominences(x, peaks)
        lb, rb = prominence_bases(x, floor)
        assert np.array_equal(lb[peaks], left) and np.array_equal(rb[peaks], right)
        assert np.array_equal(x[peaks] - np.maximum(x[lb[peaks]], x[rb[peaks]]), prom)
        assert np.all(lb[x < floor] == -1) and np.all(rb[x < floor] == -1)
        checked += peaks.size
    assert checked > 2000


def _scipy_prominent(x, peaks, pmin):
    prom, left, right = peak_prominences(x, peaks)
    keep = prom >= pmin
    return peaks[keep], prom[keep], left[keep], right[keep]


def test_prominent_peaks_are_find_peaks_bit_for_bit():
    # the early-dropping scans keep the peaks find_peaks' prominence rule keeps, with
    # scipy's prominences and bases; thresholds from none to more than any peak has
    rng = np.random.default_rng(19)
    checked = 0
    for x in _signals():
        floor = float(np.quantile(x, rng.uniform(0, 1)))
        peaks = find_peaks(x, height=floor)[0]
        spread = float(np.ptp(x)) or 1.0
        for pmin in (0.0, rng.uniform(0, 0.3) * spread, rng.uniform(0.3, 1.2) * spread):
            got, ref = prominent(x, peaks, pmin, floor), _scipy_prominent(x, peaks, pmin)
            assert np.array_equal(got[0], ref[0]) and _same_bits(got[1], ref[1])
            assert np.array_equal(got[2], ref[2]) and np.array_equal(got[3], ref[3])
            checked += ref[0].size
    assert checked > 1000


def test_prominent_peaks_of_equal_pulses_end_to_end():
    # 600 equal pulses: every scan runs over the others (<= the peak), the scans' budget
    # runs out and the one-pass bases answer, still scipy's
    x = np.tile(np.array([0.0, 0.5, 1.0, 0.5, 0.0, 0.2]), 600)
    x[::97] -= 0.05  # uneven dips
    peaks = find_peaks(x)[0]
    for pmin in (0.0, 0.6, 0.99):
        got, ref = prominent(x, peaks, pmin), _scipy_prominent(x, peaks, pmin)
        assert got[0].size == ref[0].size and all(np.array_equal(a, b) for a, b in zip(got, ref))


@pytest.mark.parametrize("distance", [None, 2, 5, 17.5])
def test_candidate_maxima_are_find_peaks_bit_for_bit(distance):
    # plateaus, ties and the height and distance rules, in find_peaks' order
    rng = np.random.default_rng(5)
    checked = 0
    for x in _signals():
        height = float(np.quantile(x, rng.uniform(0, 1)))
        ref = find_peaks(x, height=height, distance=distance)[0]
        idx = local_maxima(x)
        idx = idx[height <= x[idx]]
        assert np.array_equal(local_maxima(x, height), idx)  # the floor passes over the samples below it alone
        if distance is not None and idx.size:
            idx = idx[thin_by_distance(idx, np.argsort(x[idx]), float(distance))]
        assert np.array_equal(idx, ref)
        checked += ref.size
    assert checked > 1000


@pytest.mark.parametrize("rel_height", [0.5, 0.01, 1.0])
def test_widths_are_peak_widths_bit_for_bit(rel_height):
    checked = 0
    for x in _signals():
        peaks = find_peaks(x)[0]
        if not peaks.size:
            continue
        prom, left, right = peak_prominences(x, peaks)
        ref = peak_widths(x, peaks, rel_height=rel_height, prominence_data=(prom, left, right))[0]
        assert _same_bits(widths_at(x, peaks, rel_height, prom, left, right), ref)
        checked += peaks.size
    assert checked > 2000


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


def test_one_pole_filters_are_lfilters():
    rng = np.random.default_rng(1)
    for _ in range(100):
        n = int(rng.integers(2, 5000))
        x = rng.standard_normal(n) * 10 ** rng.uniform(-6, 3) + rng.uniform(-1, 1)
        a = math.exp(-rng.uniform(1e-4, 30))
        g = (1.0 / rng.uniform(1e-3, 10)) * (1.0 - a)
        assert _same_bits(one_pole(x, g, -g, -a, x[0], False), lfilter([g, -g], [1.0, -a], x - x[0]))
        assert _same_bits(one_pole(x, 1 - g, g - a, -a, x[0], True),
                          lfilter([1 - g, g - a], [1.0, -a], x - x[0]) + x[0])


def test_undo_highpass_is_the_trapezoid_inversion():
    rng = np.random.default_rng(2)
    for _ in range(100):
        n = int(rng.integers(1, 5000))
        y, h, tau = rng.standard_normal(n), 10 ** rng.uniform(-8, -5), 10 ** rng.uniform(-5, -2)
        assert _same_bits(undo_highpass(y, h, tau), y + cumulative_trapezoid(y, dx=h, initial=0.0) / tau)


def test_positions_read_as_np_interp_reads_them():
    rng = np.random.default_rng(5)
    for k in range(200):
        n, m = int(rng.integers(1, 3000)), int(rng.integers(1, 3000))
        f = rng.standard_normal(n) * 10 ** rng.uniform(-5, 3)
        pos = np.sort(rng.uniform(-3, n + 3, m)) if k % 2 else np.arange(m) * rng.uniform(0.5, 1.5) + rng.uniform(-5, 5)
        pos[::5] = np.round(pos[::5])  # exactly on samples too
        assert _same_bits(at_positions(f, pos), np.interp(pos, np.arange(n), f))


@pytest.mark.parametrize("sd", [0.0, 0.4])
def test_quantiser_is_the_numpy_expression(sd):
    rng = np.random.default_rng(9)
    v = rng.uniform(-1.5, 1.5, 20000)
    noise = rng.standard_normal(v.size) if sd else np.empty(0)
    codes = np.empty(v.size, np.int8)
    clipped = quantise(v, 0.1, 0.01, -25.0, sd, noise, -128.0, 127.0, codes)
    ref = (v - 0.1) / 0.01 + -25.0
    if sd:
        ref = ref + sd * noise
    ref = np.rint(ref)
    assert clipped == bool(np.any(ref > 127) or np.any(ref < -128)) and clipped
    assert codes.dtype == np.int8 and np.array_equal(codes, np.clip(ref, -128, 127).astype(np.int8))
    assert not quantise(v * 0.1, 0.0, 0.01, 0.0, sd, noise, -128.0, 127.0, codes)


@pytest.mark.parametrize("n", [1, 2, 7, 16, 1250, 1251])
def test_median_is_numpys(n):
    from instruments.analysis._kernels.baseline import median

    rng = np.random.default_rng(n)
    for x in (rng.standard_normal(n), rng.integers(0, 4, n).astype(float)):  # ties as on 8-bit records
        assert median(x) == np.median(x)


def test_correlation_adds_each_lag_in_order():
    # the cross-correlation's sums, four terms at a time, are the plain sums over j in
    # order (numpy adds a[j] b[j:j + K] to c one j after another), bit for bit, for
    # windows that are and are not multiples of four
    from instruments.analysis._kernels.correlation import correlate

    rng = np.random.default_rng(13)
    for m in (1, 3, 4, 5, 8, 611, 614):
        for K in (1, 2, 9, 615):
            a, b = rng.standard_normal(m), rng.standard_normal(m + K - 1) * 1e3
            ref = np.zeros(K)
            for j in range(m):
                ref += b[j:j + K] * a[j]
            c = np.zeros(K)
            correlate(a, b, c)
            assert _same_bits(c, ref)


def test_the_correlation_peak_is_every_lags_peak_from_the_lags_that_can_hold_it():
    # correlation_peak sums only the lags whose Cauchy-Schwarz bound reaches a value the
    # correlation takes, and their neighbours: its peak (np.argmax's) and parabola shift are
    # those of every lag's sums (correlate's, in order), bit for bit, for pulse pairs clean,
    # noisy, 8-bit-like and upside down, pure noise, amplitudes whose sums of squares would
    # underflow or overflow (the full correlation) and a nan; and b holding a's very samples
    # (its lag's bound is its value: a bound a hair too low drops the peak) beside a plateau
    # whose bound is higher and whose correlation is lower (so the lags are not all dropped)
    from instruments.analysis._kernels.correlation import correlate, correlation_peak

    rng = np.random.default_rng(29)
    for case in range(420):
        m = int(rng.integers(3, 400))
        nb = m + int(rng.integers(1, 500))

        def sech2(n, centre, width):
            return rng.uniform(0.1, 10.0) / np.cosh(np.clip((np.arange(n) - centre) / width, -300, 300)) ** 2

        width = rng.uniform(2.0, 120.0)
        a, b = sech2(m, m / 2, width), sech2(nb, rng.uniform(0, nb), width)
        kind = case % 7
        if kind == 1:
            a, b = a + rng.normal(0, 0.3, m), b + rng.normal(0, 0.3, nb)
        elif kind == 2:
            a, b = np.round(a * 20) / 20, np.round(b * 20) / 20
        elif kind == 3:
            a = -a
        elif kind == 4:
            a, b = rng.standard_normal(m), rng.standard_normal(nb)
        elif kind == 5:
            scale = 10.0 ** rng.choice([-170, 170])
            a, b = a * scale, b * scale
            if case % 4 == 1:
                b[rng.integers(nb)] = np.nan
        elif kind == 6:
            a = rng.uniform(0.1, 10.0) / np.cosh((np.arange(m) - m / 2) / rng.uniform(0.05, 0.2) / m) ** 2
            norm, total = math.sqrt(np.sum(a * a)), np.sum(a)  # total < 0.9 sqrt(m) norm: a narrow pulse
            level = 0.5 * (norm / math.sqrt(m) + norm * norm / total)  # a plateau: a higher bound, a lower value
            b = np.concatenate([np.zeros(int(rng.integers(0, 50))), a, np.zeros(int(rng.integers(0, 50))),
                                np.full(m + int(rng.integers(0, 50)), level)])[::1 if case % 2 else -1].copy()
            a = a[::1 if case % 2 else -1].copy()
            nb = b.size
        c = np.zeros(nb - m + 1)
        correlate(a, b, c)
        k = int(np.argmax(c))
        shift = 0.0
        if 0 < k < c.size - 1 and c[k - 1] - 2.0 * c[k] + c[k + 1] != 0.0:
            shift = 0.5 * (c[k - 1] - c[k + 1]) / (c[k - 1] - 2.0 * c[k] + c[k + 1])
        got_k, got_shift = correlation_peak(a, b)
        assert got_k == k, case
        assert got_shift == shift or (math.isnan(got_shift) and math.isnan(shift)), case


def test_median_of_many_records_is_numpys():
    # sorted, tied and noisy inputs of every length parity: the selection's pivots and
    # buffers give numpy's value exactly; a nan gives nan, as np.median does
    from instruments.analysis._kernels.baseline import median

    rng = np.random.default_rng(21)
    for t in range(600):
        n = int(rng.integers(1, 1500))
        x = rng.standard_normal(n) if t % 3 else rng.integers(0, 5, n).astype(float)
        if t % 5 == 0:
            x = np.sort(x)[::-1 if t % 2 else 1].copy()
        assert median(x) == np.median(x)
    x[len(x) // 2] = np.nan
    assert math.isnan(median(x))


@pytest.mark.parametrize("probe", [1.0, 10.0])
def test_front_end_is_its_filters_one_after_another(probe):
    # the scope channel's front end in one pass (both filters' recursions together, a 1x
    # probe skipped) is the input over the probe, lfilter's AC coupling, lfilter's bandwidth
    # limit about its first value, times the probe, bit for bit, each filter on or off
    from instruments.devices._kernels.acquisition import condition

    rng = np.random.default_rng(17)
    v = np.cumsum(rng.standard_normal(3000)) * 1e-3 + 0.2
    ac = np.array([0.99, -0.99, -0.98])
    lowpass = np.array([0.96, 0.04, -1.2e-3])
    off = np.full(3, np.nan)
    for a, lp in ((ac, lowpass), (ac, off), (off, lowpass), (off, off)):
        x = v / probe
        if not math.isnan(a[2]):
            x = lfilter(a[:2], [1.0, a[2]], x - x[0])
        if not math.isnan(lp[2]):
            x = lfilter(lp[:2], [1.0, lp[2]], x - x[0]) + x[0]
        assert _same_bits(condition(v, probe, a, lp), x * probe)


def test_the_selection_loops_are_numpys_indexing_and_stable_argsort():
    """kept, taken and stable_order (the analysis' selections as loops) against a[keep],
    a[idx] and np.argsort(kind="stable"), with ties (plateaus of equal heights, -0.0 beside
    0.0) and the empty and one-element cases."""
    rng = np.random.default_rng(11)
    for n in [0, 1, 2, 3, 7, 8, 9, 64, 257]:
        for values in (rng.standard_normal(n), rng.integers(0, 4, n).astype(float),
                       rng.choice([-0.0, 0.0, 1.0], n)):
            order = stable_order(values)
            assert order.dtype == np.int64 and np.array_equal(order, np.argsort(values, kind="stable")), (n, values)
            keep = rng.random(n) < 0.4
            idx = rng.integers(0, max(n, 1), n // 2) if n else np.empty(0, np.int64)
            assert _same_bits(kept(values, keep), values[keep])
            assert np.array_equal(kept(np.arange(n), keep), np.arange(n)[keep])
            assert _same_bits(taken(values, idx), values[idx])


def test_the_search_loops_are_numpys_max_argmax_and_searchsorted():
    """largest, first_largest and left_index (the analysis' np.max, np.argmax and
    np.searchsorted as loops) against numpy: ties (the first largest, bit for bit: of 0.0
    and -0.0 the first, as numba's np.max, where numpy's may give either), nan anywhere (nan,
    np.argmax the first nan, searchsorted's nan after every number), values off both ends
    and on the samples."""
    rng = np.random.default_rng(5)
    for n in [1, 2, 3, 8, 9, 257]:
        for values in (rng.standard_normal(n), rng.integers(0, 4, n).astype(float), rng.choice([-0.0, 0.0], n)):
            cases = [values]
            for k in {0, n // 2, n - 1}:
                with_nan = values.copy()
                with_nan[k] = np.nan
                cases.append(with_nan)
            if n > 2:
                two = cases[-1].copy()
                two[1] = np.nan
                cases.append(two)
                signs = values.copy()  # nans of other signs and payloads: the first one's bits
                signs[[1, n - 1]] = -np.nan, np.array(0x7FF8000000000001).view(np.float64)
                cases.append(signs)
            for a in cases:
                assert _same_bits(np.array([largest(a)]), a[[np.argmax(a)]]), a
                assert largest(a) == np.max(a) or np.isnan(np.max(a)) and np.isnan(largest(a)), a
                assert first_largest(a) == np.argmax(a), a
            grid = np.sort(values)
            probes = np.concatenate([grid, grid + 1e-9, grid - 1e-9, [-np.inf, np.inf, np.nan, -1e9, 1e9]])
            for v in probes:
                assert left_index(grid, v) == np.searchsorted(grid, v), (grid, v)


def _first_crest(f):
    """The definition, sample by sample: the first sample above half of max(f - f[0]), then
    on while the next does not fall; None where f never rises above f[0]."""
    rise = [x - f[0] for x in f]
    top = max(rise, default=0.0)
    if top <= 0:
        return None
    i = next(k for k, r in enumerate(rise) if r > 0.5 * top)
    while i + 1 < len(rise) and not rise[i + 1] < rise[i]:
        i += 1
    return i


@pytest.mark.parametrize("threads", [1, 2])
def test_first_crests_of_many_shots_are_each_shots_own(threads):
    import numba

    from instruments.analysis.find import first_peak_time, first_peak_times
    from instruments.errors import InstrumentError

    rng = np.random.default_rng(5)
    f = np.round(rng.standard_normal((37, 3, 200)).cumsum(axis=2))  # plateaus: ties at the crest
    f[4, 1] = f[4, 1, 0] - np.abs(f[4, 1] - f[4, 1, 0])  # never above its first sample: no crest
    f[5, 2] = 7.0  # flat
    h = 2.5e-7
    was = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        t = first_peak_times(f, [2, 0], h)
    finally:
        numba.set_num_threads(was)
    assert t.shape == (37, 2)
    for s in range(37):
        for k, row in enumerate((2, 0)):
            i = _first_crest(list(f[s, row]))
            assert (math.isnan(t[s, k]) if i is None else t[s, k] == i * h)
            single = first_peak_time(f[s, row], h)
            assert single == (None if i is None else i * h)
    assert np.isnan(t[5, 0]) and np.isnan(first_peak_times(f, [1], h)[4, 0])
    for call, message in ((lambda: first_peak_times(f, [3], h), r"rows = \[3\]: allowed 0 .. 2"),
                          (lambda: first_peak_times(f, [-1], h), r"rows = \[-1\]"),
                          (lambda: first_peak_times(f[0], [0], h), r"shape \(3, 200\): allowed \(shots, rows"),
                          (lambda: first_peak_time(f[0], h), r"shape \(3, 200\): allowed one dimension")):
        with pytest.raises(InstrumentError, match=message):
            call()
