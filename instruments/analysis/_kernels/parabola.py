"""Least-squares parabola through a few samples (numba): what np.polyfit(x, y, 2) gives,
without its set-up cost, for the many short fits of a study."""
import math

from numerics.jit import jit


@jit
def _det3(a, b, c, d, e, f, g, h, i):
    """Determinant of [[a, b, c], [d, e, f], [g, h, i]]."""
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


@jit
def parabola(x, y):
    """(a, b, c) of the least-squares fit y = a x^2 + b x + c; nan if x has fewer than
    three distinct values. The normal equations are solved by Cramer's rule: centre x and
    keep it of order 1 (sample units) so that they stay well conditioned."""
    s0 = float(x.shape[0])
    s1 = s2 = s3 = s4 = t0 = t1 = t2 = 0.0
    for k in range(x.shape[0]):
        xk = x[k]
        x2 = xk * xk
        s1 += xk
        s2 += x2
        s3 += x2 * xk
        s4 += x2 * x2
        t0 += y[k]
        t1 += xk * y[k]
        t2 += x2 * y[k]
    det = _det3(s4, s3, s2, s3, s2, s1, s2, s1, s0)
    if det == 0.0:
        return math.nan, math.nan, math.nan
    a = _det3(t2, s3, s2, t1, s2, s1, t0, s1, s0) / det
    b = _det3(s4, t2, s2, s3, t1, s1, s2, t0, s0) / det
    c = _det3(s4, s3, t2, s3, s2, t1, s2, s1, t0) / det
    return a, b, c
