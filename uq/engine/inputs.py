"""Input quantities of a propagation: distributions, shapes, correlation, draws.

An input is a scipy.stats frozen distribution (one scalar), a float (a known constant,
not sampled), or :class:`Input` (a distribution with a shape: that many identically
distributed scalars, e.g. one noise value per beam and range gate; independent, or with a
correlation matrix between its elements, e.g. a Gauss-Markov process in time). A joint
distribution such as :class:`UniformCircle` (a point uniform on a circle: the unit phase
vector of a harmonic) draws its last axis together.

Correlation between scalar inputs is imposed with a Gaussian copula: correlated standard
normal scores ``z = L e`` (L the Cholesky factor of the correlation matrix) are mapped
through each input's inverse CDF. For normal inputs the given coefficient is the Pearson
correlation exactly; for other distributions it is the correlation of the normal scores,
and the GUM uses it as the Pearson coefficient (a close approximation).
"""
from dataclasses import dataclass, field

import functools

import numpy as np
from scipy.special import ndtr

from uq.constants import SEMIDEFINITE_TOLERANCE


@dataclass(frozen=True)
class Input:
    """A distribution with a shape: ``prod(shape)`` independent draws per sample.

    Parameters
    ----------
    distribution : scipy.stats frozen distribution, joint distribution or float
    shape : tuple of int
    correlation : ndarray, optional
        Correlation matrix between the ``prod(shape)`` elements (C order), imposed with
        the Gaussian copula like the correlation between inputs.

    Examples
    --------
    Three independent draws per trial of a 0.1 m/s noise, summed: the GUM gives
    u = 0.1 sqrt(3) exactly (the model is linear):

    >>> from scipy import stats
    >>> import uq
    >>> noise = uq.Input(stats.norm(0.0, 0.1), (3,))
    >>> result = uq.propagate(lambda noise: noise.sum(axis=-1), {"noise": noise},
    ...                       n=20_000, seed=1)
    >>> round(float(result["y_gum_u"]), 6)
    0.173205
    """

    distribution: object
    shape: tuple = ()
    correlation: object = None


class UniformCircle:
    """A point uniform on a circle of radius r: ``r (cos phi, sin phi)``, phi uniform on
    [0, 2 pi). Its two coordinates are drawn together (the last axis of an
    :class:`Input`'s shape must be 2). Each coordinate is arcsine-distributed with mean 0
    and standard deviation r / sqrt(2); the two are uncorrelated (the GUM's view of it).

    From two independent normal scores (z1, z2) the point is ``r z / |z|``: the angle of
    a standard bivariate normal is uniform (its density is rotation invariant).
    """

    joint_size = 2
    #: :meth:`transform` may write its points over the scores (``out``).
    transforms_in_place = True

    def __init__(self, radius=1.0):
        self.radius = float(radius)

    def mean(self):
        return 0.0

    def std(self):
        return self.radius / np.sqrt(2.0)

    def transform(self, scores, out=None):
        """Points from normal scores, shape (..., 2) -> (..., 2) (into `out`, which may
        be `scores`). ``|z|^2 = z1 z1 + z2 z2`` (one addition: what a sum over the last
        axis gives, without its strided reduction)."""
        out = np.empty(scores.shape) if out is None else out
        shape = (scores.shape[0] if scores.ndim > 1 else 1,
                 int(np.prod(scores.shape[1:-1])), 2)       # (n, points, 2): views of both
        points, into = scores.reshape(shape), out.reshape(shape)
        if into.size and not np.shares_memory(into, out):
            raise ValueError("out must take the shape (n, points, 2) without a copy")
        for k in range(points.shape[1]):    # 1-D columns: numpy's fast strided loops
            first, second = points[:, k, 0], points[:, k, 1]
            norm = np.sqrt(first * first + second * second)
            np.multiply(first, self.radius, out=into[:, k, 0])
            into[:, k, 0] /= norm
            np.multiply(second, self.radius, out=into[:, k, 1])
            into[:, k, 1] /= norm
        return out

    def __repr__(self):
        return f"UniformCircle(radius={self.radius:g})"


def moments(distribution):
    """(mean, standard deviation) of a distribution (a frozen scipy one, or anything with
    ``mean()`` and ``std()``), kept for the next run that uses the same object (the
    scenario layer shares one frozen distribution per spec)."""
    try:
        return _kept_moments(distribution)
    except TypeError:                        # unhashable: computed anew
        return _kept_moments.__wrapped__(distribution)


@functools.lru_cache(maxsize=1024)
def _kept_moments(distribution):
    return float(distribution.mean()), float(distribution.std())


@dataclass(frozen=True)
class InputSet:
    """Random inputs laid out as columns of a (samples, dimension) matrix.

    Built by :func:`input_set`. Names are sorted, so the same set of inputs always takes
    the same columns (common random numbers across the scenes of a sweep).
    """

    names: tuple
    shapes: dict
    distributions: dict
    constants: dict
    offsets: dict
    dimension: int
    cholesky: np.ndarray = field(repr=False)

    def means(self):
        """Input means, each of its shape."""
        return {name: np.full(self.shapes[name], self._moments[name][0])
                for name in self.names}

    def standard_uncertainties(self):
        """Per-column standard deviations, shape (dimension,)."""
        return np.concatenate([np.full(int(np.prod(self.shapes[name])),
                                       self._moments[name][1])
                               for name in self.names]) if self.names else np.zeros(0)

    @functools.cached_property
    def _moments(self):
        """(mean, standard deviation) of each input, computed once (scipy's frozen
        mean() and std() cost ~50 us each; :func:`moments` keeps them across runs)."""
        return {name: moments(self.distributions[name]) for name in self.names}

    def correlation_matrix(self):
        """Column correlation matrix, shape (dimension, dimension)."""
        return self.cholesky @ self.cholesky.T

    def column_names(self):
        """Input name of each column."""
        return [name for name in self.names for _ in range(int(np.prod(self.shapes[name])))]

    def values(self, scores, overwrite=False):
        """Input arrays from normal scores of shape (n, dimension).

        Returns dict name -> array of shape (n, *shape) of the random inputs only.
        With `overwrite` the scores (C-contiguous float64) are turned into the values in
        place: no new matrix, and the returned arrays are views of `scores`.
        """
        # independent inputs (identity Cholesky factor): no product needed
        independent = not self.dimension or np.array_equal(self.cholesky, np.eye(self.dimension))
        correlated = scores if independent else scores @ self.cholesky.T
        # normal inputs, loc + scale z, in one pass over the whole matrix; each is then a
        # (strided) view of it. Other columns get (0, 1): unchanged, so in place is safe
        normal = self._normal_columns
        affine = None
        if normal is not None:
            in_place = overwrite or correlated is not scores        # (a product is ours)
            affine = np.multiply(correlated, normal[1], out=correlated if in_place else None)
            if np.any(normal[0]):                   # errors are mostly centred: no pass
                affine += normal[0]
        arrays = {}
        for name in self.names:
            start = self.offsets[name]
            size = int(np.prod(self.shapes[name]))
            columns = slice(start, start + size)
            distribution = self.distributions[name]
            shape = (len(scores),) + tuple(self.shapes[name])
            if hasattr(distribution, "joint_size"):
                scores_of = correlated[:, columns].reshape(shape)    # (a view here)
                if getattr(distribution, "transforms_in_place", False) and \
                        (overwrite or correlated is not scores):
                    arrays[name] = distribution.transform(scores_of, out=scores_of)
                else:
                    arrays[name] = distribution.transform(scores_of)
                continue
            value = affine[:, columns] if _is_normal(distribution) \
                else _inverse_cdf(distribution, correlated[:, columns])
            arrays[name] = value.reshape(shape)
        return arrays

    @functools.cached_property
    def _normal_columns(self):
        """(loc, scale) per column, (0, 1) for non-normal inputs; None without normals
        (computed once: scipy's frozen mean() and std() cost ~50 us each)."""
        if not any(_is_normal(self.distributions[name]) for name in self.names):
            return None
        laid = [self._moments[name] if _is_normal(self.distributions[name]) else (0.0, 1.0)
                for name in self.names for _ in range(int(np.prod(self.shapes[name])))]
        return np.array(laid).T


def input_set(inputs, correlation=None):
    """Lay out `inputs` (see module docstring) and their correlation as an :class:`InputSet`.

    Parameters
    ----------
    inputs : dict
        name -> frozen distribution, float or :class:`Input`.
    correlation : dict, optional
        ``{(name_a, name_b): rho}`` between scalar random inputs, -1 < rho < 1.
    """
    shapes, distributions, constants, blocks = {}, {}, {}, {}
    for name, spec in inputs.items():
        distribution, shape = (spec.distribution, tuple(spec.shape)) if isinstance(spec, Input) \
            else (spec, ())
        if isinstance(distribution, (int, float, np.number)):
            constants[name] = float(distribution) if not shape else np.full(shape, float(distribution))
            continue
        if not (hasattr(distribution, "ppf") or hasattr(distribution, "joint_size")):
            raise TypeError(f"input {name!r}: expected a scipy.stats frozen distribution or a "
                            f"float, got {type(distribution).__name__}")
        if hasattr(distribution, "joint_size") and shape[-1:] != (distribution.joint_size,):
            raise ValueError(f"input {name!r}: a joint distribution of "
                             f"{distribution.joint_size} needs a shape ending in it")
        distributions[name], shapes[name] = distribution, shape
        if isinstance(spec, Input) and spec.correlation is not None:
            blocks[name] = np.asarray(spec.correlation, dtype=float)
    names = tuple(sorted(distributions))
    offsets, start = {}, 0
    for name in names:
        offsets[name] = start
        start += int(np.prod(shapes[name]))
    cholesky = _cholesky(correlation or {}, names, shapes, offsets, start, blocks)
    return InputSet(names, shapes, distributions, constants, offsets, start, cholesky)


def _cholesky(correlation, names, shapes, offsets, dimension, blocks=None):
    matrix = np.eye(dimension)
    for name, block in (blocks or {}).items():
        size = int(np.prod(shapes[name]))
        if block.shape != (size, size) or not np.allclose(block, block.T) or \
                not np.allclose(np.diag(block), 1.0):
            raise ValueError(f"input {name!r}: its correlation must be a symmetric "
                             f"{size} x {size} matrix with a unit diagonal")
        matrix[offsets[name]:offsets[name] + size, offsets[name]:offsets[name] + size] = block
    for pair, rho in correlation.items():
        a, b = pair
        for name in (a, b):
            if name not in names:
                raise ValueError(f"correlation names {name!r}, which is not a random input")
            if shapes[name] != ():
                raise ValueError(f"correlation: {name!r} has shape {shapes[name]}; only "
                                 "scalar inputs can be correlated")
        if not -1 < rho < 1 or a == b:
            raise ValueError(f"correlation {pair}: need two different inputs and -1 < rho < 1")
        matrix[offsets[a], offsets[b]] = matrix[offsets[b], offsets[a]] = rho
    try:
        return np.linalg.cholesky(matrix)
    except np.linalg.LinAlgError:
        return semidefinite_root(matrix)


def semidefinite_root(matrix):
    """A square root L (``L L^T = matrix``) of a correlation matrix that Cholesky refuses
    but that is positive semidefinite: singular (a Gauss-Markov process in its fully
    correlated limit, correlation time -> inf or beams at one instant: every element the
    same score) or positive definite only to rounding. From the eigen-decomposition,
    with the eigenvalues that rounding pushed below 0 set to 0 (backward stable: L L^T
    equals the matrix to rounding). ValueError if an eigenvalue is negative beyond
    :data:`~uq.constants.SEMIDEFINITE_TOLERANCE` per row (inconsistent correlations)."""
    values, vectors = np.linalg.eigh(matrix)
    if values[0] < -SEMIDEFINITE_TOLERANCE * len(matrix):
        raise ValueError(f"correlation matrix is not positive semidefinite (eigenvalue "
                         f"{values[0]:.3g})")
    return vectors * np.sqrt(np.clip(values, 0.0, None))


def _is_normal(distribution):
    return getattr(getattr(distribution, "dist", None), "name", None) == "norm"


def _inverse_cdf(distribution, z):
    """Values of a non-normal input with normal scores `z`; exact in both tails.

    (Normal inputs are ``loc + scale z``, made for all of them at once by
    :meth:`InputSet.values`: no round trip through probabilities.) Uniform inputs are
    ``a + w Phi(z)``. Others use ``ppf(Phi(z))`` for z <= 0 and ``isf(Phi(-z))`` for
    z > 0, so that upper-tail probabilities keep their relative precision.
    """
    family = getattr(getattr(distribution, "dist", None), "name", None)
    if family == "uniform":
        # ppf(p) = a + w p, written out (scipy's generic ppf makes several argument-
        # checking passes). One tail is enough here: the value's absolute error is
        # w eps/2 for any p, within an ulp of the support (no long tail to resolve)
        low, high = distribution.support()
        value = ndtr(z)
        value *= high - low
        value += low
        return value
    lower = z <= 0
    out = np.empty_like(z)
    out[lower] = distribution.ppf(ndtr(z[lower]))
    out[~lower] = distribution.isf(ndtr(-z[~lower]))
    return out
