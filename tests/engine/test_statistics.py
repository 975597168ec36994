"""Streaming statistics equal their in-memory definitions."""
import numpy as np
import pytest

from uq.engine.statistics import (StreamingStatistics, batch_statistics, coverage_interval, tail_capacity, unwrap)


def direct_interval(values, p=0.95):
    m = len(values)
    s = np.sort(values)
    q = int(np.floor(p * m + 0.5))
    r = (m - q) // 2 if (m - q) % 2 == 0 else (m - q + 1) // 2
    return s[r - 1], s[r + q - 1]


@pytest.mark.parametrize("m", [20, 21, 40, 41, 1000, 12345])
def test_symmetric_interval_is_jcgm101_ranks(m, rng):
    values = rng.standard_normal(m)
    s = np.sort(values)
    assert coverage_interval(s, s, m) == direct_interval(values)


@pytest.mark.parametrize("m", [1, 2, 19])
def test_no_interval_from_too_few_values(m):
    assert np.isnan(coverage_interval(np.arange(m), np.arange(m), m)).all()


# every value kept / tails from the start / tails taking over after 15000 of 20000 values
STORED = [2**23, 0, 15_000]


@pytest.mark.parametrize("stored", STORED)
@pytest.mark.parametrize("chunk", [1, 7, 100, 5000])
def test_streaming_equals_in_memory(chunk, stored, rng):
    values = rng.gamma(2.0, size=(10_000, 2))
    stats = StreamingStatistics((2,), tail_capacity(len(values)) + 1, stored_values=stored)
    for start in range(0, len(values), chunk):
        stats.update(values[start:start + chunk])
    result = stats.result()
    np.testing.assert_allclose(result["mean"], values.mean(axis=0), rtol=1e-13)
    np.testing.assert_allclose(result["u"], values.std(axis=0, ddof=1), rtol=1e-12)
    for j in range(2):
        assert (result["low"][j], result["high"][j]) == direct_interval(values[:, j])


@pytest.mark.parametrize("stored", STORED)
def test_shortest_interval(stored, rng):
    values = rng.exponential(size=4000)
    stats = StreamingStatistics((), tail_capacity(4000), stored_values=stored // 5)
    for start in range(0, 4000, 1000):
        stats.update(values[start:start + 1000])
    low, high = stats.result(kind="shortest")["low"], stats.result(kind="shortest")["high"]
    s = np.sort(values)
    q = int(np.floor(0.95 * 4000 + 0.5))
    widths = s[q:] - s[:4000 - q]
    assert high - low == pytest.approx(widths.min())


def test_moments_stay_accurate_with_a_large_offset(rng):
    values = 1e8 + rng.standard_normal(200_000)
    stats = StreamingStatistics((), 10)
    for chunk in np.split(values, 100):
        stats.update(chunk)
    assert stats.result()["u"] == pytest.approx(values.std(ddof=1), rel=1e-7)


def test_unwrap():
    np.testing.assert_allclose(unwrap(np.array([359.0, 1.0, 180.0]), 0.0), [-1.0, 1.0, 180.0])
    np.testing.assert_allclose(unwrap(np.array([1.0]), 359.0), [361.0])


@pytest.mark.parametrize("stored", STORED)
def test_nan_excluded_and_counted(stored, rng):
    stats = StreamingStatistics((), 100)
    stats.update(np.array([1.0, np.nan, 3.0]))
    result = stats.result()
    assert result["n_valid"] == 2 and result["mean"] == 2.0
    # intervals of the finite values only, whichever way they are kept
    values = rng.normal(size=4000)
    values[::7] = np.nan
    values[::11] = np.inf
    stats = StreamingStatistics((), tail_capacity(4000) + 1, stored_values=stored // 5)
    for start in range(0, 4000, 500):
        stats.update(values[start:start + 500])
    finite = values[np.isfinite(values)]
    result = stats.result()
    assert result["n_valid"] == finite.size
    assert (result["low"], result["high"]) == direct_interval(finite)
    values[1::13] = -np.inf
    batch = batch_statistics(values)
    finite = values[np.isfinite(values)]
    assert (batch["low"], batch["high"]) == direct_interval(finite)


@pytest.mark.parametrize("m", [40, 999, 16384])
def test_batch_statistics_partition_equals_sorted_interval(m):
    """The one-partition path picks exactly the order statistics of coverage_interval."""
    from uq.engine.statistics import batch_statistics, coverage_interval
    values = np.random.default_rng(m).standard_normal((m, 3))
    batch = batch_statistics(values)
    for j in range(3):
        ordered = np.sort(values[:, j])
        assert (batch["low"][j], batch["high"][j]) == coverage_interval(ordered, ordered, m)


def test_numerical_error_of_a_direction_at_north_is_not_a_wrap_artefact():
    """Batch means of a direction near 0/360 must not be wrapped apart (359.9 vs 0.1):
    the numerical error is of the order u / sqrt(N), not ~100 deg."""
    import scipy.stats as st
    import uq
    out = uq.propagate(lambda x: np.mod(x, 360.0), {"x": st.norm(0.0, 0.5)}, n=2**17, seed=1,
                       circular=("y",))
    # 2 s of 8 batch means of 2^14 trials: about 2 * 0.5 / sqrt(2^17) = 0.003 deg
    assert float(out["y_mc_numerical_error"]) < 0.02


def test_batch_statistics_do_not_keep_the_batch_alive():
    """Endpoints returned as views would keep every 2^14-trial batch in memory (8 bytes
    per trial: 800 MB at 10^8 trials); they must own their data."""
    from uq.engine.statistics import batch_statistics
    result = batch_statistics(np.random.default_rng(1).standard_normal((2**14, 3)))
    assert all(result[key].base is None or result[key].base.size <= 3
               for key in ("low", "high"))


def test_tail_buffer_keeps_exactly_the_smallest():
    from uq.engine.statistics import _Tail
    rng = np.random.default_rng(4)
    tail, seen = _Tail(500), []
    for size in (100, 3000, 10, 7000, 1):
        values = rng.standard_normal(size)
        seen.append(values)
        tail.add(values[values < tail.threshold])
    expected = np.sort(np.concatenate(seen))[:500]
    np.testing.assert_array_equal(np.sort(tail.values()), expected)


@pytest.mark.parametrize("threads", [1, 2, 3, 4])
def test_the_order_statistics_do_not_depend_on_the_threads(threads, rng, monkeypatch):
    """The elements' order statistics are shared between threads by contiguous parts;
    each part writes only its own endpoints, so any number of threads gives the exact
    sorted-array ranks (JCGM 101 7.7.2), element by element."""
    from uq.engine import statistics
    monkeypatch.setattr(statistics, "STATISTICS_THREADS", threads)
    values = rng.standard_normal((50_000, 7, 3)) * np.arange(1, 22).reshape(7, 3)
    stats = StreamingStatistics((7, 3), tail_capacity(50_000) + 1, expected=50_000)
    stats.add(values, 2**14)
    result = stats.result()
    ordered = np.sort(values, axis=0)
    low, high = statistics._symmetric_ranks(50_000, 0.95)
    np.testing.assert_array_equal(result["low"], ordered[low])
    np.testing.assert_array_equal(result["high"], ordered[high])


def test_element_parts_cover_every_element_once():
    from uq.engine.statistics import element_parts
    for size in (1, 2, 3, 7, 27, 100):
        for threads in (1, 2, 4):
            covered = np.concatenate([np.arange(size)[part]
                                      for part in element_parts(size, threads)])
            np.testing.assert_array_equal(covered, np.arange(size))


def test_smaller_summary_batches_leave_the_results_unchanged(rng):
    """Summaries of sub-batches (the standard errors' batches) are those of each
    sub-batch alone (batch_statistics), and the merged results are bit for bit those of
    summaries of whole batches: the merges follow the moments' batches only."""
    values = rng.gamma(2.0, size=(3 * 4096, 2))
    whole = StreamingStatistics((2,), tail_capacity(len(values)) + 1)
    parts = StreamingStatistics((2,), tail_capacity(len(values)) + 1)
    assert len(whole.add(values, 4096, summarize=True)) == 3
    summaries = parts.add(values, 4096, summarize=True, summary_size=1024)
    assert [start for start, _ in summaries] == list(range(0, len(values), 1024))
    for start, summary in summaries:
        expected = batch_statistics(values[start:start + 1024])
        for key in ("mean", "u", "low", "high"):
            np.testing.assert_allclose(summary[key], expected[key], rtol=1e-12)
    for key, value in whole.result().items():
        np.testing.assert_array_equal(value, parts.result()[key])


@pytest.fixture
def one_pass(monkeypatch):
    """Runs of any length take the one-pass batches (uq.engine.passkernels)."""
    from uq.engine import statistics
    monkeypatch.setattr(statistics, "ONE_PASS_MIN_TRIALS", 0)


def _sorted_ranks(values):
    """Ascending values of every element and the JCGM 101 7.7.2 ranks of their count."""
    from uq.engine.statistics import _symmetric_ranks
    return np.sort(values, axis=0), _symmetric_ranks(len(values), 0.95)


RUN_CASES = {
    "normal": lambda rng, n: rng.standard_normal((n, 3)),
    "heavy tails": lambda rng, n: rng.standard_cauchy((n, 3)),
    "ties": lambda rng, n: rng.integers(0, 7, (n, 3)).astype(float),
    "constant": lambda rng, n: np.full((n, 3), 2.5),
    # ascending through the run: the first batch's brackets miss the run's ranks
    "drifting": lambda rng, n: np.sort(rng.standard_normal((n, 3)), axis=0),
}


@pytest.mark.parametrize("summary_size", [2048, 4096])
@pytest.mark.parametrize("case", sorted(RUN_CASES))
def test_run_and_batch_endpoints_from_the_brackets_are_exact(case, summary_size, rng,
                                                              one_pass):
    """The endpoints of every sub-batch and of the run, selected among the values kept
    inside the run's brackets (set at its first sub-batch), are the exact order
    statistics, whether the brackets hold the ranks (normal, heavy tails, ties) or miss
    them (a constant output, values drifting through the run: all values decide)."""
    n = 5 * 4096 + 123
    values = RUN_CASES[case](rng, n)
    stats = StreamingStatistics((3,), tail_capacity(n) + 1, expected=n)
    summaries = []
    for start in range(0, n, 8192):                   # chunks of two batches
        summaries += [(start + first, summary) for first, summary in stats.add(
            values[start:start + 8192], 4096, summarize=True, summary_size=summary_size)]
    assert len(summaries) == 5 * 4096 // summary_size
    for first, summary in summaries:
        ordered, (low, high) = _sorted_ranks(values[first:first + summary_size])
        np.testing.assert_array_equal(summary["low"], ordered[low])
        np.testing.assert_array_equal(summary["high"], ordered[high])
    result = stats.result()
    ordered, (low, high) = _sorted_ranks(values)
    np.testing.assert_array_equal(result["low"], ordered[low])
    np.testing.assert_array_equal(result["high"], ordered[high])
    if case in ("normal", "heavy tails"):             # the brackets were used, and held
        from uq.engine import passkernels
        assert np.all(stats._run.state == passkernels.GLOBAL_COUNTING)
        assert np.all(stats._run.kept < 0.1 * n)      # a few per cent of the values


def test_run_endpoints_exact_when_the_kept_values_overflow(rng, monkeypatch, one_pass):
    """Too little room for the values inside the brackets: counted on, detected, and
    the run's endpoints come from all values."""
    from uq.engine import statistics
    monkeypatch.setattr(statistics._RunBrackets, "ROOM_FRACTION", 0.0)
    monkeypatch.setattr(statistics._RunBrackets, "MIN_ROOM", 300)
    values = rng.standard_normal((6 * 4096, 2))
    stats = StreamingStatistics((2,), tail_capacity(len(values)) + 1, expected=len(values))
    stats.add(values, 4096, summarize=True)
    assert np.all(stats._run.kept >= 300)             # overflowed
    ordered, (low, high) = _sorted_ranks(values)
    np.testing.assert_array_equal(stats.result()["low"], ordered[low])
    np.testing.assert_array_equal(stats.result()["high"], ordered[high])


def test_an_element_with_nan_gives_up_its_brackets(rng, one_pass):
    """A NaN after the first batch: that element's run endpoints come from all its
    finite values; the other element keeps its brackets."""
    from uq.engine import passkernels
    values = rng.standard_normal((4 * 4096, 2))
    values[3 * 4096 + 5, 1] = np.nan
    stats = StreamingStatistics((2,), tail_capacity(len(values)) + 1, expected=len(values))
    stats.add(values, 4096, summarize=True)
    assert list(stats._run.state) == [passkernels.GLOBAL_COUNTING, passkernels.GLOBAL_OFF]
    result = stats.result()
    for j in range(2):
        finite = values[:, j][np.isfinite(values[:, j])]
        assert (result["low"][j], result["high"][j]) == direct_interval(finite)


def _assert_same_runs(first, second):
    """The (summaries, result) of runs `first` equal those of `second`, bit for bit."""
    for (one, result_one), (two, result_two) in zip(first, second):
        assert [start for start, _ in one] == [start for start, _ in two]
        for (_, a), (_, b) in zip(one, two):
            for key in a:
                np.testing.assert_array_equal(a[key], b[key])
        for key in result_one:
            np.testing.assert_array_equal(result_one[key], result_two[key])


def test_short_and_long_runs_give_the_same_numbers(rng, monkeypatch):
    """The one-pass batches of long runs (from ONE_PASS_MIN_TRIALS) and the kernels of
    short runs: the same summaries and results, bit for bit (exact order statistics, the
    same sums in the same order), a direction included."""
    from uq.engine import statistics
    values = rng.standard_normal((3 * 4096 + 77, 2, 3)) * [1.0, 2.0, 3.0]
    values[:, 1] = np.mod(350.0 + 8.0 * values[:, 1], 360.0)   # about north
    outputs = []
    for threshold in (2**40, 0):
        monkeypatch.setattr(statistics, "ONE_PASS_MIN_TRIALS", threshold)
        for reference in (None, np.full((2, 3), 355.0)):
            stats = StreamingStatistics((2, 3), tail_capacity(len(values)) + 1, reference,
                                        expected=len(values))
            summaries = stats.add(values, 4096, summarize=True, summary_size=2048)
            outputs.append((summaries, stats.result()))
    _assert_same_runs(outputs[:2], outputs[2:])


@pytest.mark.parametrize("stored_values, expected", [(1, True), (6 * 9000, False)])
def test_long_runs_in_the_tails_give_the_numbers_of_short_runs(stored_values, expected, rng,
                                                               monkeypatch):
    """Past the store's budget (from the first values, or spilled in the middle of the
    run) a long run's batches take the one-pass kernel and the compiled candidates of
    the tails: the same summaries and results, bit for bit, as the short runs' numpy
    tails, a direction, NaN and infinities included, over several chunks."""
    from uq.engine import statistics
    n = 6 * 4096 + 77
    values = rng.standard_normal((n, 2, 3)) * [1.0, 2.0, 3.0]
    values[:, 1] = np.mod(350.0 + 8.0 * values[:, 1], 360.0)   # about north
    values[[5, 9000, 20000], 0, 0] = [np.nan, np.inf, -np.inf]
    outputs = []
    for threshold in (2**40, 0):
        monkeypatch.setattr(statistics, "ONE_PASS_MIN_TRIALS", threshold)
        for reference in (None, np.full((2, 3), 355.0)):
            stats = StreamingStatistics((2, 3), tail_capacity(n) + 1, reference,
                                        stored_values=stored_values,
                                        expected=n if expected else None)
            summaries = []
            for start in range(0, n, 8192):
                assert stats._stored == (start == 0 or (not expected and start < 9000))
                summaries += stats.add(values[start:start + 8192], 4096, summarize=True,
                                       summary_size=2048)
            assert not stats._stored
            outputs.append((summaries, stats.result()))
    _assert_same_runs(outputs[:2], outputs[2:])
    finite = values[:, 0, 0][np.isfinite(values[:, 0, 0])]
    assert (outputs[2][1]["low"][0, 0], outputs[2][1]["high"][0, 0]) == \
        direct_interval(finite)
