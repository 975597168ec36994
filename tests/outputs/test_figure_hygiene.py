"""Figure hygiene over every figure every shipped scenario draws (run small): no text
outside the canvas or over other text, every drawn series in a legend and every legend
entry drawn, no unexplained colour, and a caption for each. The checker itself is tested
on figures made wrong on purpose, so that it cannot pass by missing what it looks for."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from tests.outputs.figure_hygiene import problems  # noqa: E402
from tests.outputs.small_runs import measurement_names, small_result  # noqa: E402
from uq.outputs.figures import caption, figure_plan  # noqa: E402


@pytest.mark.parametrize("name", measurement_names())
def test_every_figure_of_a_shipped_scenario_is_readable(name):
    dataset = small_result(name)
    plan = figure_plan(dataset)
    assert plan, f"{name} draws no figure"
    for stem, function in plan:
        figure = function(dataset)
        try:
            assert problems(figure) == [], stem
        finally:
            plt.close(figure)
        assert len(caption(stem)) > 40, f"{stem}: no caption says what it shows"


def _figure():
    figure, ax = plt.subplots(figsize=(4, 3), constrained_layout=True)
    return figure, ax


def test_the_checker_finds_a_title_cut_at_the_canvas_edge():
    figure, ax = _figure()
    figure.suptitle("a title far too long for a figure four inches wide, cut at both edges")
    assert any("outside the canvas" in p for p in problems(figure))
    plt.close(figure)


def test_the_checker_finds_overlapping_text():
    figure, ax = _figure()
    ax.text(0.5, 0.5, "first words")
    ax.text(0.52, 0.5, "second words")
    assert any("overlaps" in p for p in problems(figure))
    plt.close(figure)


def test_the_checker_finds_a_legend_entry_for_nothing_drawn_and_a_series_not_listed():
    figure, ax = _figure()
    ax.plot([0, 1, 2], [0, 1, 4], color="C0", label="drawn")
    ax.plot([0, 1, 2], [4, 1, 0], color="C1", label="drawn, not listed")
    ax.legend(handles=[Line2D([], [], color="C0", label="drawn"),
                       Line2D([], [], color="C2", ls=":", marker="s", label="never drawn")])
    found = problems(figure)
    assert any("'never drawn'" in p and "nothing in view" in p for p in found), found
    assert any("'drawn, not listed'" in p and "no legend lists it" in p for p in found), found
    plt.close(figure)


def test_the_checker_finds_a_line_whose_data_lies_outside_the_view():
    figure, ax = _figure()
    ax.plot([0, 1], [0, 1], color="C0", label="in view")
    ax.plot([5, 6], [5, 6], color="C1", label="out of view")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend()
    assert any("'out of view'" in p for p in problems(figure))
    plt.close(figure)


def test_the_checker_finds_colours_no_legend_names():
    figure, ax = _figure()
    ax.plot([0, 1, 2], [0, 1, 4], color="C0")
    ax.plot([0, 1, 2], [4, 1, 0], color="C3")
    assert any("no legend names it" in p for p in problems(figure))
    plt.close(figure)


def test_a_clean_figure_passes():
    figure, ax = _figure()
    ax.plot([0, 1, 2], [0, 1, 4], color="C0", label="rising")
    ax.plot([0, 1, 2], [4, 1, 0], color="C1", label="falling")
    ax.set_xlabel("x [m]")
    ax.legend()
    assert problems(figure) == []
    plt.close(figure)
