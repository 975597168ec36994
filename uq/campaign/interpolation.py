"""Interpolation weights of the campaign's tables: trigonometric in the wind direction,
Lagrange polynomials in frequency and in log speed.

Each function returns the weights of the table's nodes at the query points, so that a
table is interpolated by one contraction (``np.einsum``) whatever the quantity's shape.

* :func:`periodic_weights`: the trigonometric interpolant of n equally spaced nodes on the
  circle (n odd), exact for every trigonometric polynomial of degree up to (n - 1) / 2
  (the Dirichlet kernel ``sin(n x / 2) / (n sin(x / 2))``, Zygmund 1959, Ch. X); with
  ``degree`` lower, the least-squares fit of that degree (the higher harmonics, which the
  quantity is known not to have, are dropped).
* :func:`lagrange_weights`: the cubic (four-point) Lagrange interpolant on a uniform
  grid, the stencil centred on the query (error O(h^4 f'''')).
* :func:`log_lagrange_weights`: the Lagrange polynomial through every node, in log(x).

References
----------
.. [1] Zygmund, A. (1959). Trigonometric Series. Cambridge University Press, Ch. X.
"""
import numpy as np


def periodic_nodes(count):
    """`count` equally spaced angles on [0, 2 pi) [rad], the first at 0."""
    return 2.0 * np.pi * np.arange(count) / count


def periodic_weights(angle, count, degree=None):
    """Weights (n, count) of the nodes :func:`periodic_nodes` at `angle` [rad] (n,):
    the trigonometric interpolant (count odd) or its truncation to harmonics up to
    `degree` (module docstring)."""
    if count % 2 == 0:
        raise ValueError("periodic_weights: an odd number of nodes (no Nyquist harmonic)")
    top = (count - 1) // 2 if degree is None else min(degree, (count - 1) // 2)
    x = np.subtract.outer(np.asarray(angle, float), periodic_nodes(count))
    harmonics = np.arange(1, top + 1)
    return (1.0 + 2.0 * np.cos(x[..., None] * harmonics).sum(axis=-1)) / count


def lagrange_weights(x, start, step, count):
    """(index (n, 4), weights (n, 4)) of the cubic Lagrange interpolant at `x` (n,) on
    the uniform grid ``start + step k``, k = 0 ... count - 1 (count >= 4); the four
    nodes around x (clamped at the ends, where the polynomial extrapolates at most half
    a step)."""
    t = (np.asarray(x, float) - start) / step
    first = np.clip(np.floor(t).astype(int) - 1, 0, count - 4)
    index = first[:, None] + np.arange(4)
    weights = np.ones(index.shape)
    for j in range(4):
        for m in range(4):
            if m != j:
                weights[:, j] *= (t - index[:, m]) / (j - m)
    return index, weights


def log_lagrange_weights(x, nodes):
    """Weights (n, len(nodes)) of the Lagrange polynomial through every node, in
    log(x) (x and nodes > 0)."""
    u = np.log(np.asarray(x, float))[:, None]
    v = np.log(np.asarray(nodes, float))
    weights = np.ones((u.shape[0], v.size))
    for j in range(v.size):
        for m in range(v.size):
            if m != j:
                weights[:, j] *= (u[:, 0] - v[m]) / (v[j] - v[m])
    return weights
