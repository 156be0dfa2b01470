"""A missing measurement predicted from the given ones: the conditional mean of the survey's multivariate normal.

With the survey's mean mu and covariance S over its keys, the measurements given G and the ones wanted M:
E[x_M | x_G] = mu_M + S_MG S_GG^-1 (x_G - mu_G), and the spread left, sqrt(diag(S_MM - S_MG S_GG^-1 S_GM)), is
reported beside each prediction. The solve is a Cholesky factor computed in a fixed order (``population.cholesky``)
and substitutions in a fixed order: the same bits on every machine.

Which survey: the shipped one of the person's sex. ElliMann ships ANSUR II's women (``ansur2_female``) and no
men's statistics, so a male file's missing measurement is refused, naming it, unless a statistics file is given.
Of a file's values, those that are the survey's measurements by definition take part (the five, neck, thigh,
calf, crotch_height, and the neck base and the shoulder tips' breadth, which the survey holds too); the survey's
flexed biceps is not ElliMann's relaxed upper arm, so upper_arm never does.
"""

import math

import numpy as np

from ..errors import ElliMannError
from ..synthesis.population import cholesky, load_population

SHIPPED_STATISTICS = {"female": "ansur2_female"}  # sex -> the shipped survey a missing measurement comes from
NOT_PREDICTORS = ("upper_arm",)  # ElliMann keys whose survey namesake is measured otherwise


class PredictionError(ElliMannError):
    """A missing measurement that cannot be predicted (no statistics for the sex, or none of its predictors)."""


def statistics_for(sex, statistics=None):
    """The Population a missing measurement of a ``sex`` ('female', 'male' or None) is predicted from: ``statistics``
    (a name or a path) when given, else the shipped survey of that sex; PredictionError naming what is missing."""
    if statistics is not None:
        return load_population(statistics)
    name = SHIPPED_STATISTICS.get(sex or "female")
    if name is None:
        shipped = ", ".join(f"{n} ({s})" for s, n in SHIPPED_STATISTICS.items())
        raise PredictionError(
            f"no {sex} survey statistics are shipped to predict it (ElliMann ships {shipped}); give the "
            "measurement, or a statistics file of men (docs/population.md)"
        )
    return load_population(name)


def conditional_mean(population, given, wanted):
    """({key: cm}, {key: sd cm}): the mean of each ``wanted`` key of ``population`` given ``given`` {key: cm}
    (keys the survey does not hold, or ``NOT_PREDICTORS``, are left out), and the spread left about it."""
    keys = list(population.keys)
    missing = [key for key in wanted if key not in keys]
    if missing:
        raise PredictionError(f"{missing[0]} is not in the survey {population.name!r} ({', '.join(keys)})")
    used = [key for key in keys if key in given and key not in wanted and key not in NOT_PREDICTORS]
    if not used:
        raise PredictionError(f"nothing given that the survey {population.name!r} holds, to predict it from")
    g = [keys.index(key) for key in used]
    m = [keys.index(key) for key in wanted]
    cov = population.covariance
    factor = cholesky(cov[np.ix_(g, g)], used)
    deviation = [float(given[key]) - population.mean[i] for key, i in zip(used, g)]
    weights = _solve(factor, deviation)  # S_GG^-1 (x_G - mu_G)
    means, spreads = {}, {}
    for key, i in zip(wanted, m):
        cross = [cov[i, j] for j in g]
        mean = population.mean[i]
        for c, w in zip(cross, weights):
            mean += c * w
        explained = _solve(factor, cross)
        variance = cov[i, i]
        for c, e in zip(cross, explained):
            variance -= c * e
        means[key] = float(mean)
        spreads[key] = math.sqrt(max(float(variance), 0.0))
    return means, spreads


def _solve(factor, rhs):
    """x with L L^T x = rhs, by forward then back substitution in a fixed order."""
    n = len(rhs)
    y = [0.0] * n
    for i in range(n):
        total = float(rhs[i])
        for j in range(i):
            total -= factor[i, j] * y[j]
        y[i] = total / factor[i, i]
    x = [0.0] * n
    for i in reversed(range(n)):
        total = y[i]
        for j in range(i + 1, n):
            total -= factor[j, i] * x[j]
        x[i] = total / factor[i, i]
    return x
