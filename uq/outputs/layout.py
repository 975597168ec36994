"""Text that fits its figure: titles wrapped to the canvas, legends in as many columns as
the canvas holds (no numbers, no I/O).

A figure is as wide as its panels; a title or a legend under the panels is not, and
matplotlib's constrained layout does not widen the canvas for them: a long one is cut at
the canvas edge. Widths are measured with matplotlib's own text metrics (the font the
figure uses), so a wrapped title or a legend's columns fit on the canvas whatever the
words.
"""
from matplotlib.font_manager import FontProperties
from matplotlib.textpath import TextToPath

#: Share of the canvas's width a title or legend may take (the rest: margins) [1].
USABLE_WIDTH = 0.94
#: matplotlib's legend spacing in units of the font size (its rcParams defaults):
#: handle length, pad between handle and text, space between columns, border pads.
HANDLE_LENGTH, HANDLE_TEXT_PAD, COLUMN_SPACING, BORDER = 2.0, 0.8, 2.0, 1.0

_MEASURE = TextToPath()


def text_width(text, fontsize):
    """Width of a one-line text at `fontsize` [points] in the default font [points]."""
    prop = FontProperties(size=fontsize)
    width, _, _ = _MEASURE.get_text_width_height_descent(text, prop, ismath=False)
    return width


def usable_width(figure):
    """Width a line of text may take on `figure` [points]."""
    return figure.get_figwidth() * 72.0 * USABLE_WIDTH


def wrapped(text, width, fontsize):
    """`text` with line breaks so that no line is wider than `width` [points] (each
    given line wrapped on its own, at spaces)."""
    out = []
    for paragraph in text.split("\n"):
        line = ""
        for word in paragraph.split(" "):
            candidate = f"{line} {word}" if line else word
            if line and text_width(candidate, fontsize) > width:
                out.append(line)
                line = word
            else:
                line = candidate
        out.append(line)
    return "\n".join(out)


def suptitle(figure, text, fontsize=9):
    """The figure's title, wrapped to its width."""
    return figure.suptitle(wrapped(text, usable_width(figure), fontsize), fontsize=fontsize)


def title(ax, text, fontsize=9):
    """An axes' title, wrapped to the axes' width (set the axes' layout first)."""
    width = ax.get_position().width * usable_width(ax.figure)
    return ax.set_title(wrapped(text, width, fontsize), fontsize=fontsize)


def legend_columns(figure, labels, fontsize, longest=None):
    """The most columns (at most `longest`, default all) in which a legend of `labels`
    fits the figure's width: matplotlib fills a legend column by column."""
    widths = [text_width(label, fontsize) + (HANDLE_LENGTH + HANDLE_TEXT_PAD) * fontsize
              for label in labels]
    limit = usable_width(figure)
    for columns in range(min(longest or len(labels), len(labels)), 0, -1):
        rows, large = divmod(len(labels), columns)      # as matplotlib's Legend splits
        counts = [rows + 1] * large + [rows] * (columns - large)
        starts = [sum(counts[:k]) for k in range(columns)]
        parts = [widths[start:start + count] for start, count in zip(starts, counts)]
        total = sum(max(part) for part in parts) + COLUMN_SPACING * fontsize * (
            len(parts) - 1) + 2 * BORDER * fontsize
        if total <= limit:
            return columns
    return 1


def legend_below(figure, handles, labels, fontsize=7, longest=None, **options):
    """A legend under the panels, in as many columns as fit the canvas (at most
    `longest`)."""
    if not handles:
        return None
    columns = legend_columns(figure, labels, fontsize, longest)
    if options.get("title"):
        options["title"] = wrapped(options["title"], usable_width(figure),
                                   options.get("title_fontsize", fontsize))
    return figure.legend(handles, labels, loc="outside lower center", fontsize=fontsize,
                         ncols=columns, frameon=False, **options)
