"""What makes a figure readable, as checks on a drawn matplotlib Figure.

:func:`problems` lists, in words, every place where a figure

* puts text outside its canvas (a cut legend, title or label),
* puts text over other text (overlapping labels, ticks or legend entries),
* draws a labelled series that no legend lists,
* lists a legend entry that nothing drawn in view matches,
* draws several data series in one panel that no legend tells apart.

The figure is drawn first (Agg, the size and dpi it is saved at), so every position is
the one in the file. A legend entry is matched to a drawn artist by its label, or, for
the proxy handles of a shared legend, by colour, line style and marker.
"""
import itertools

import matplotlib.colors as mcolors
import numpy as np
from matplotlib.collections import Collection, PathCollection, PolyCollection, QuadMesh
from matplotlib.container import BarContainer, ErrorbarContainer
from matplotlib.patches import Patch
from matplotlib.axis import Axis
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.text import Text

#: Pixels a text may reach beyond the canvas or into another text (anti-aliasing, the
#: rounding of a glyph's extent) before it counts.
SLACK = 1.5


def problems(figure, dpi=130):
    """Every readability problem of `figure`, as sentences ([] when there is none)."""
    figure.set_dpi(dpi)
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    texts = _texts(figure, renderer)
    found = _outside(figure, texts) + _overlapping(texts)
    found += _legend_problems(figure)
    return found


def _texts(figure, renderer):
    """(text, bbox) of every non-empty text drawn: visible, under visible parents."""
    out = []
    for text in _visible(figure, Text):
        if not text.get_text().strip():
            continue
        bbox = text.get_window_extent(renderer)
        if bbox.width > 0 and bbox.height > 0:
            out.append((text, bbox))
    return out


def _visible(artist, kind):
    """The artists of `kind` under `artist` that are drawn (they and every parent
    visible); of an axis, only the ticks it draws (those in view) and its labels."""
    if not artist.get_visible():
        return
    if isinstance(artist, kind):
        yield artist
    if isinstance(artist, Axis):
        children = [artist.label, artist.offsetText]
        for tick in artist._update_ticks():               # the ticks in view only
            children += [tick.label1, tick.label2]
    else:
        children = artist.get_children()
    for child in children:
        yield from _visible(child, kind)


def _outside(figure, texts):
    canvas = figure.bbox
    return [f"text {text.get_text()!r} reaches outside the canvas "
            f"({bbox.x0:.0f}..{bbox.x1:.0f} x {bbox.y0:.0f}..{bbox.y1:.0f} px of "
            f"{canvas.width:.0f} x {canvas.height:.0f})"
            for text, bbox in texts
            if bbox.x0 < -SLACK or bbox.y0 < -SLACK or bbox.x1 > canvas.x1 + SLACK
            or bbox.y1 > canvas.y1 + SLACK]


def _overlapping(texts):
    found = []
    for (a, box_a), (b, box_b) in itertools.combinations(texts, 2):
        width = min(box_a.x1, box_b.x1) - max(box_a.x0, box_b.x0)
        height = min(box_a.y1, box_b.y1) - max(box_a.y0, box_b.y0)
        if width > SLACK and height > SLACK:
            found.append(f"text {a.get_text()!r} overlaps text {b.get_text()!r}")
    return found


def _legends(figure):
    legends = [lg for lg in figure.legends if lg.get_visible()]
    legends += [ax.get_legend() for ax in figure.axes
                if ax.get_legend() is not None and ax.get_legend().get_visible()]
    return legends


def _series(ax):
    """The data series an axes draws: lines with data in view, scatter and histogram
    collections, patches (bars grouped by their container), error bars (by their
    container), but not the axes' own spines, grids or a colorbar's mesh."""
    in_errorbars = {id(a) for c in ax.containers if isinstance(c, ErrorbarContainer)
                    for a in _flatten(c)}
    out = [line for line in ax.get_lines() if line.get_visible() and _in_view(line)
           and id(line) not in in_errorbars]
    out += [c for c in ax.collections if c.get_visible() and not isinstance(c, QuadMesh)
            and id(c) not in in_errorbars and len(c.get_paths())
            and isinstance(c, (PathCollection, PolyCollection))]
    grouped = {id(p) for c in ax.containers if isinstance(c, BarContainer) for p in c}
    out += [p for p in ax.patches if p.get_visible() and id(p) not in grouped]
    out += [c.patches[0] if isinstance(c, BarContainer) else c for c in ax.containers
            if (isinstance(c, BarContainer) and len(c.patches)) or
            (isinstance(c, ErrorbarContainer) and _errorbar_in_view(c))]
    return out


def _flatten(container):
    for item in container:
        if isinstance(item, (tuple, list)):
            yield from item
        elif item is not None:
            yield item


def _errorbar_in_view(container):
    line = container.lines[0]
    return line is None or _in_view(line)


def _in_view(line):
    """Has the line a finite point inside its axes' limits (an axvline/axhline has)?"""
    x, y = (np.asarray(v, dtype=float) for v in line.get_data(orig=False))
    if line.get_transform() != line.axes.transData:        # axvline/axhline: blended
        return True
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.any():
        return False
    if line.get_marker() in (None, "None", "", " ") and finite.sum() < 2:
        return False                   # one point and no marker: nothing is drawn
    (x0, x1), (y0, y1) = sorted(line.axes.get_xlim()), sorted(line.axes.get_ylim())
    inside = finite & (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    return bool(inside.any())


def _labelled(artist):
    label = artist.get_label()
    return bool(label) and not label.startswith("_")


def _style(artist):
    """(colour, line style, marker) of an artist, for matching legend entries."""
    if isinstance(artist, ErrorbarContainer):
        artist = artist.lines[0] if artist.lines[0] is not None else artist.lines[2][0]
    if isinstance(artist, Line2D):
        plain = artist.get_linestyle() in ("None", "", " ")
        colour = artist.get_markeredgecolor() if plain else artist.get_color()
        if isinstance(colour, str) and colour in ("auto", "none"):
            colour = artist.get_color()
        return (_hex(colour), "None" if plain else artist.get_linestyle(),
                str(artist.get_marker()) if artist.get_marker() not in (None, "None", "")
                else "None")
    if isinstance(artist, Collection):
        colours = artist.get_facecolor() if len(artist.get_facecolor()) and \
            np.asarray(artist.get_facecolor())[0][3] > 0 else artist.get_edgecolor()
        return (_hex(colours[0]) if len(colours) else None, "-", "None")
    if isinstance(artist, Patch):
        fill = artist.get_fill() and artist.get_facecolor()[3] > 0
        return (_hex(artist.get_facecolor() if fill else artist.get_edgecolor()), "-", "None")
    return (None, None, None)


def _hex(colour):
    try:
        return mcolors.to_hex(colour)
    except ValueError:
        return None


def _achromatic(colour):
    """Black or grey: a key entry that shows a line style or marker, not a colour."""
    if colour is None:
        return True
    r, g, b = mcolors.to_rgb(colour)
    return max(r, g, b) - min(r, g, b) < 0.02


def _matches(entry, drawn):
    """Does a legend entry of style `entry` describe a drawn style? The same colour and
    line style and marker; or, for a style key (black or grey), the same line style and
    marker in any colour; or, for a colour key (a plain solid line or a patch), the same
    colour in any line style."""
    colour, line, marker = entry
    if entry == drawn:
        return True
    if _achromatic(colour):
        return (line, marker) == drawn[1:]
    if line in ("-", "solid") and marker == "None":
        return colour == drawn[0]
    return False


def _legend_problems(figure):
    found = []
    legends = _legends(figure)
    entries = {}                              # label -> style of its handle
    for legend in legends:
        for handle, text in zip(legend.legend_handles, legend.get_texts()):
            entries[text.get_text()] = _style(handle) if handle is not None else None
    drawn = [series for ax in figure.axes for series in _series(ax)]
    styles = [_style(s) for s in drawn]
    labels = {s.get_label() for s in drawn if _labelled(s)}
    for series, style in zip(drawn, styles):
        listed = _labelled(series) and series.get_label() in entries
        keyed = any(e is not None and _matches(e, style) for e in entries.values())
        if _labelled(series) and legends and not (listed or keyed):
            found.append(f"the series {series.get_label()!r} is drawn but no legend "
                         "lists it")
    for label, entry in entries.items():
        if label in labels or (entry is not None and any(_matches(entry, s)
                                                          for s in styles)):
            continue
        found.append(f"the legend lists {label!r} but nothing in view is drawn like it")
    for ax in figure.axes:
        found += _unexplained_colours(ax, entries)
    return found


def _unexplained_colours(ax, entries):
    """Several data series of different colours in one panel need a legend that names
    each colour (one series needs none: its axis label names it)."""
    series = [s for s in _series(ax) if not _reference_line(s)]
    styles = {_style(s) for s in series}
    if len({style[0] for style in styles}) < 2:
        return []
    keys = [e for e in entries.values() if e is not None]
    missing = sorted({style[0] for style in styles
                      if style[0] is not None and not any(_matches(e, style) for e in keys)
                      and not any(e[0] == style[0] for e in keys)})
    title = ax.get_title() or ax.get_ylabel() or "a panel"
    return [f"in {title!r} the colour {c} is drawn but no legend names it" for c in missing]


def _reference_line(series):
    """A horizontal or vertical reference line (axhline/axvline, a zero line)."""
    if not isinstance(series, Line2D):
        return False
    if series.get_transform() != series.axes.transData:
        return True
    x, y = (np.asarray(v, dtype=float) for v in series.get_data(orig=False))
    return len(x) <= 2 and (np.ptp(x) == 0 or np.ptp(y) == 0)


