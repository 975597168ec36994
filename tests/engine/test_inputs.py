"""Input layout and the transform of normal scores into input values."""
import numpy as np
import pytest
import scipy.stats as st

from uq.engine.inputs import Input, input_set

INPUTS = {"a": st.norm(1.0, 2.0), "b": Input(st.norm(0.0, 0.5), (2,)), "c": st.uniform(-1, 2),
          "d": st.expon(), "k": 3.0}


@pytest.mark.parametrize("correlation", [None, {("a", "c"): 0.5}])
def test_in_place_transform_gives_the_same_values(correlation, rng):
    layout = input_set(INPUTS, correlation)
    scores = rng.standard_normal((1000, layout.dimension))
    kept = scores.copy()
    plain = layout.values(scores)
    assert np.array_equal(scores, kept)                         # not touched by default
    in_place = layout.values(scores, overwrite=True)
    for name in plain:
        assert np.array_equal(in_place[name], plain[name]), name
    assert set(plain) == {"a", "b", "c", "d"} and plain["b"].shape == (1000, 2)


def test_values_follow_each_distribution(rng):
    """loc + scale z for normals, ppf(Phi(z)) otherwise, column by column."""
    layout = input_set(INPUTS)
    scores = rng.standard_normal((5, layout.dimension))
    values = layout.values(scores)
    column = {name: layout.offsets[name] for name in layout.names}
    np.testing.assert_allclose(values["a"], 1.0 + 2.0 * scores[:, column["a"]], rtol=1e-15)
    np.testing.assert_allclose(values["b"], 0.5 * scores[:, column["b"]:column["b"] + 2],
                               rtol=1e-15)
    np.testing.assert_allclose(values["c"], -1 + 2 * st.norm.cdf(scores[:, column["c"]]),
                               rtol=0, atol=1e-15)
    np.testing.assert_allclose(values["d"], st.expon.ppf(st.norm.cdf(scores[:, column["d"]])),
                               rtol=1e-12)


def test_uniform_circle_is_uniform_in_angle_and_has_the_gum_moments():
    """r z / |z| of two normal scores: angle uniform (Kolmogorov-Smirnov against U(0, 2 pi)
    at 1e4 draws, p > 1e-3), radius exactly r, and the GUM's mean 0 and u = r / sqrt(2)."""
    import scipy.stats as st
    from uq.engine.inputs import UniformCircle
    circle = UniformCircle(2.0)
    points = circle.transform(np.random.default_rng(5).standard_normal((10_000, 2)))
    np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 1]), 2.0, rtol=1e-15)
    angle = np.mod(np.arctan2(points[:, 1], points[:, 0]), 2 * np.pi)
    assert st.kstest(angle, st.uniform(0, 2 * np.pi).cdf).pvalue > 1e-3
    assert circle.mean() == 0.0 and circle.std() == pytest.approx(np.sqrt(2.0))
    s = input_set({"c": Input(circle, (3, 2))})
    np.testing.assert_allclose(s.standard_uncertainties(), np.sqrt(2.0))
    np.testing.assert_array_equal(s.correlation_matrix(), np.eye(6))


def test_an_input_with_a_correlation_between_its_elements():
    """Input(normal, (3,), correlation=R): the draws have correlation R (3 sigma of a
    correlation at 2e5 draws: 3 (1 - rho^2) / sqrt(N) < 0.007) and the GUM sees R."""
    import scipy.stats as st
    rho = np.array([[1.0, 0.8, 0.5], [0.8, 1.0, 0.8], [0.5, 0.8, 1.0]])
    s = input_set({"e": Input(st.norm(0, 2.0), (3,), correlation=rho)})
    np.testing.assert_allclose(s.correlation_matrix(), rho, atol=1e-15)
    values = s.values(np.random.default_rng(1).standard_normal((200_000, 3)))["e"]
    np.testing.assert_allclose(np.corrcoef(values.T), rho, atol=0.007)
    with pytest.raises(ValueError, match="unit diagonal"):
        input_set({"e": Input(st.norm(), (2,), correlation=np.array([[1, 2], [2, 1.0]]) * 0.5)})


def test_a_singular_correlation_is_its_fully_correlated_limit():
    """A Gauss-Markov correlation whose time constant dwarfs the beam spacing rounds to
    all ones (singular: Cholesky refuses it); the square root of the semidefinite matrix
    draws every element with the same score (L L^T = the matrix to rounding, 1e-15);
    an indefinite matrix (inconsistent correlations) is still refused."""
    from uq.engine.inputs import semidefinite_root
    from uq.physics.ins import gauss_markov_correlation
    ones = gauss_markov_correlation(np.arange(4.0), 1e20)
    assert np.array_equal(ones, np.ones((4, 4)))
    root = semidefinite_root(ones)
    np.testing.assert_allclose(root @ root.T, ones, atol=1e-15)
    laid = input_set({"x": Input(st.norm(0, 1), (4,), correlation=ones)})
    draws = laid.values(np.random.default_rng(1).standard_normal((1000, 4)))["x"]
    np.testing.assert_allclose(draws, draws[:, :1] * np.ones((1, 4)), atol=1e-12)
    with pytest.raises(ValueError, match="not positive semidefinite"):
        semidefinite_root(np.array([[1.0, 0.9, -0.9], [0.9, 1.0, 0.9], [-0.9, 0.9, 1.0]]))
