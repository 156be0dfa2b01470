"""The ridge body model: a request's measurements -> a body's vertices and joints by ridge regression over a set's
body space (core.synthesis.body_space: many bodies, stored as the regression's sufficient statistics). The same
interface as core.body.model.IdwBodyModel (``body(request)``, ``weights(request)``), so the correction
(core.body.correct) follows it unchanged.

- Inputs: every measurement of the request the space knows (the five, the six extras, the further ones of
  core.measure.further), standardized by the bodies' mean and spread. A request that gives a subset gets the
  regression on that subset (fitted on first use in milliseconds and kept): the model the cross-validation
  validated, not a full model fed guesses for the missing inputs.
- Outputs: the body's vertices (on its floor) and joints, as offsets from the bodies' mean.
- Tolerances: each input's tape error (cm, taken as its standard deviation; ISO 20685's allowances by default,
  ``"exact"`` for measurements read on a mesh, or the user's own). A fit trained on inputs carrying that noise
  minimises, in expectation, ``|Y - X B|^2 + N tr(B^T S B)`` (S the noise's covariance): ridge with the penalty
  ``N (lambda I + S)`` in standardized units, exact in closed form (no random draws). An input known to a
  centimetre on a body spread over a few therefore counts less than one known to a millimetre.
- Regularisation: lambda by leave-one-out cross-validation over the space's own bodies, in closed form (the
  hat matrix's diagonal; the bodies' Gram matrix gives every residual's size), the expected error of the tape's
  noise added to each held-out body's: a grid over 1e-8..1e2, then golden section on log lambda in the best
  cell (the choice moves continuously with the bodies: no last-bit decision).
"""

from dataclasses import dataclass

import numpy as np

from ..measure.further import FURTHER_ALLOWANCE
from ..measurements import ISO_ALLOWANCE

DEFAULT_TOLERANCES = {**ISO_ALLOWANCE, **FURTHER_ALLOWANCE}
EXACT = "exact"
LAMBDAS = np.logspace(-8.0, 2.0, 41)  # the cross-validation's grid (standardized inputs, per body)
REFINE_STEPS = 30  # golden-section steps on log lambda inside the best grid cell


# The fit's products and its inverse in numpy's own loops, not BLAS/LAPACK: OpenBLAS splits even an 11 x 11
# inverse across its threads, and a body made with 1 or 2 threads differed in the last bits (the same answer on
# every machine, tests/core/test_same_answer.py). The fit's matrices are at most bodies x bodies (86) and the
# body one (21,) x (21, 40116) product: under a millisecond each (docs/body_space.md, Speed).
PRODUCTS = {(2, 2): "ij,jk->ik", (2, 1): "ij,j->i", (1, 2): "j,jk->k", (1, 1): "j,j->"}  # by the operands' ndim


def product(a, b):
    """a @ b (2-D or 1-D operands) summed in numpy's own loops, whatever BLAS's threads."""
    a, b = np.ascontiguousarray(a, float), np.ascontiguousarray(b, float)
    return np.einsum(PRODUCTS[a.ndim, b.ndim], a, b)


def spd_inverse(a):
    """The inverse of a symmetric positive definite matrix (a few dozen rows) by Cholesky, in numpy's loops: each
    row's sums vectorized, since a fit inverts one 74 times (core.synthesis.population.cholesky, one scalar at a
    time, keeps the bits of the sampled populations and checks a survey's covariance)."""
    n = len(a)
    low = np.zeros((n, n))
    for j in range(n):
        low[j, j] = np.sqrt(a[j, j] - np.sum(low[j, :j] ** 2))
        low[j + 1 :, j] = (a[j + 1 :, j] - np.sum(low[j + 1 :, :j] * low[j, :j], axis=1)) / low[j, j]
    inverse_low = np.zeros((n, n))  # low^-1 by forward substitution
    for i in range(n):
        inverse_low[i, i] = 1.0 / low[i, i]
        inverse_low[i, :i] = -np.sum(low[i, :i, None] * inverse_low[:i, :i], axis=0) / low[i, i]
    return product(inverse_low.T, inverse_low)


def resolve_tolerances(tolerances, keys):
    """(len(keys),) cm: ``tolerances`` None (ISO 20685's allowances), "exact" (zeros) or {key: cm} (the
    allowances for the keys it does not name). ValueError (one line) for a negative or non-finite tolerance."""
    if isinstance(tolerances, str):
        if tolerances != EXACT:
            raise ValueError(f"tolerances: {tolerances!r} is not '{EXACT}', None or {{measurement: cm}}")
        return np.zeros(len(keys))
    given = dict(tolerances or {})
    for key, value in given.items():
        if not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0.0:
            raise ValueError(f"tolerances: {key} {value!r} must be a finite number of cm, 0 or more")
    return np.array([float(given.get(key, DEFAULT_TOLERANCES.get(key, 0.0))) for key in keys])


@dataclass(frozen=True)
class RidgeFit:
    """The regression on ``keys`` with ``tolerances`` (cm): its ``lam``, the leave-one-out error it expects
    (``cv_mm``: root mean square over the vertices and joints, the tape's noise included), ``coefficients``
    (M, S): a standardized request's weights on the space's directions, and ``dual`` (N, S): on its bodies."""

    keys: tuple
    tolerances: tuple
    lam: float
    cv_mm: float
    coefficients: np.ndarray
    dual: np.ndarray


class RidgeBodyModel:
    """Ridge regression over ``space`` (a BodySpace) with the inputs' ``tolerances`` (see resolve_tolerances);
    ``lam``: a fixed regularisation instead of the cross-validated one (tests, benches)."""

    def __init__(self, space, tolerances=None, lam=None):
        self.space = space
        self.tolerances = tolerances
        self.lam = lam
        self.directions = np.asarray(space.directions, np.float32)
        self.points = len(space.mean) // 3
        self._fits = {}

    def inputs(self, request):
        """The space's keys the request gives, in the space's order."""
        return tuple(key for key in self.space.keys if key in request)

    def fit(self, keys, tolerances=None):
        """The RidgeFit on ``keys`` (measured once per keys and tolerances, then kept)."""
        keys = tuple(keys)
        sigma = resolve_tolerances(self.tolerances if tolerances is None else tolerances, keys)
        label = (keys, tuple(sigma.tolist()))
        if label not in self._fits:
            self._fits[label] = self._fit(keys, sigma)
        return self._fits[label]

    def _fit(self, keys, sigma):
        space = self.space
        unknown = [key for key in keys if key not in space.keys]
        if unknown or not keys:
            raise ValueError(f"ridge body model: inputs {', '.join(unknown) or '(none)'} are not the space's")
        index = [space.keys.index(key) for key in keys]
        x = space.standardized[:, index]
        r = space.r[:, index]
        noise = (sigma / space.scale[index]) ** 2
        count = len(x)
        gram = space.gram
        rtr, xtgx = product(r.T, r), product(product(x.T, gram), x)

        def score(log_lam):
            lam = 10.0**log_lam
            inverse = spd_inverse(rtr + count * (lam * np.eye(len(keys)) + np.diag(noise)))
            hat = product(product(x, inverse), x.T) + 1.0 / count
            rest = np.eye(count) - hat
            loo = np.einsum("ij,ij->i", product(rest, gram), rest) / (1.0 - np.diag(hat)) ** 2
            spread = product(product(inverse, xtgx), inverse)  # B B^T of the fitted coefficients
            return (loo.mean() + float(product(noise, np.diag(spread)))) / self.points

        if self.lam is not None:
            return self._solved(keys, sigma, float(self.lam), score(np.log10(self.lam)), x, r, rtr, noise)
        logs = np.log10(LAMBDAS)
        scores = np.array([score(v) for v in logs])
        best = int(np.argmin(scores))
        low, high = logs[max(best - 1, 0)], logs[min(best + 1, len(logs) - 1)]
        ratio = (np.sqrt(5.0) - 1.0) / 2.0
        c, d = high - ratio * (high - low), low + ratio * (high - low)
        fc, fd = score(c), score(d)
        for _ in range(REFINE_STEPS):
            if fc < fd:
                high, d, fd = d, c, fc
                c = high - ratio * (high - low)
                fc = score(c)
            else:
                low, c, fc = c, d, fd
                d = low + ratio * (high - low)
                fd = score(d)
        log_lam = 0.5 * (low + high)
        return self._solved(keys, sigma, 10.0**log_lam, score(log_lam), x, r, rtr, noise)

    @staticmethod
    def _solved(keys, sigma, lam, score, x, r, rtr, noise):
        inverse = spd_inverse(rtr + len(x) * (lam * np.eye(len(keys)) + np.diag(noise)))
        cv = np.sqrt(max(score, 0.0)) * 1e3
        return RidgeFit(keys, tuple(sigma.tolist()), lam, cv, product(r, inverse), product(x, inverse))

    def standardized(self, request, keys):
        index = [self.space.keys.index(key) for key in keys]
        values = np.array([float(request[key]) for key in keys])
        return (values - self.space.centre[index]) / self.space.scale[index]

    def flat(self, request, tolerances=None):
        """(P,) the predicted body, flattened (vertices on the floor, then joints)."""
        keys = self.inputs(request)
        found = self.fit(keys, tolerances)
        weights = product(found.coefficients, self.standardized(request, keys))
        return self.space.mean + product(weights, self.directions)

    def body(self, request, tolerances=None):
        """(vertices (V, 3), joints (24, 3)) m for ``request`` ({key: cm}; every key the space knows is an input),
        its lowest point on z = 0."""
        vertices, joints = self.space.split(self.flat(request, tolerances))
        floor = float(vertices[:, 2].min())
        vertices[:, 2] -= floor
        joints[:, 2] -= floor
        return vertices, joints

    def weights(self, request, tolerances=None):
        """(N,) the space's bodies' weights in the prediction (they sum to 1; they may be negative)."""
        keys = self.inputs(request)
        found = self.fit(keys, tolerances)
        return product(found.dual, self.standardized(request, keys)) + 1.0 / len(self.space)
