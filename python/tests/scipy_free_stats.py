"""A chi-square goodness-of-fit p-value without scipy: bins expecting
fewer than 5 draws are pooled into one, and the p-value is the regularized
upper incomplete gamma function Q(dof / 2, statistic / 2) (its series below
a + 1, Lentz's continued fraction above)."""

import math

import numpy as np


def _upper_gamma_q(a, x):
    if x <= 0:
        return 1.0
    log_prefix = a * math.log(x) - x - math.lgamma(a)
    if x < a + 1:
        term = total = 1.0 / a
        k = a
        for _ in range(10_000):
            k += 1
            term *= x / k
            total += term
            if abs(term) < abs(total) * 1e-15:
                break
        return max(0.0, 1.0 - total * math.exp(log_prefix))
    tiny = 1e-300
    b = x + 1 - a
    c = 1 / tiny
    d = 1 / b
    h = d
    for i in range(1, 10_000):
        an = -i * (i - a)
        b += 2
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1 / d
        delta = d * c
        h *= delta
        if abs(delta - 1) < 1e-15:
            break
    return math.exp(log_prefix) * h


def chi_square_p(observed, expected):
    """The p-value of `observed` counts against `expected` ones (same total)."""
    observed = np.asarray(observed, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    big = expected >= 5
    obs = np.append(observed[big], observed[~big].sum())
    exp = np.append(expected[big], expected[~big].sum())
    keep = exp > 0
    if np.any(obs[~keep] > 0):
        return 0.0  # draws where nothing was expected
    obs, exp = obs[keep], exp[keep]
    statistic = float(np.sum((obs - exp) ** 2 / exp))
    return _upper_gamma_q((len(obs) - 1) / 2, statistic / 2)


def test_the_p_value_matches_known_quantiles():
    # chi-square with 10 degrees of freedom: P(X > 18.307) = 0.05,
    # P(X > 2.558) = 0.99; with 1: P(X > 3.841) = 0.05.
    assert abs(_upper_gamma_q(5, 18.307 / 2) - 0.05) < 1e-4
    assert abs(_upper_gamma_q(5, 2.558 / 2) - 0.99) < 1e-4
    assert abs(_upper_gamma_q(0.5, 3.841 / 2) - 0.05) < 1e-4
