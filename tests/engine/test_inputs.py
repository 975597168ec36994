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
