"""``uq list``: the shipped scenarios, each with its whole description, wrapped to the
terminal's width."""
import shutil

from uq.cli.common import EXIT_OK, say

#: Narrowest line the descriptions are wrapped to [characters] (a terminal that reports
#: a smaller width still gets readable lines; the width is ``COLUMNS``, else the
#: terminal's, else 80).
MIN_WIDTH = 60
#: Fewest characters of description beside a name, however long the names [characters].
MIN_TEXT = 30


def add_parser(commands):
    listing = commands.add_parser("list", help="the shipped scenarios with their "
                                  "descriptions; run one with 'uq run NAME'")
    listing.set_defaults(handler=command)
    return listing


def command(args):
    from uq.pipeline.shipped import describe, shipped_names, shipped_path
    names = shipped_names()
    width = max(len(name) for name in names) + 2
    columns = max(MIN_WIDTH, shutil.get_terminal_size().columns)
    say(args, "\n".join(scenario_lines(name, describe(shipped_path(name)), width, columns)
                        for name in names))
    return EXIT_OK


def scenario_lines(name, description, width, columns):
    """``name  description``: the whole description, wrapped into lines of at most
    `columns` characters, those after the first indented by `width` (the names'
    column); one line for an empty description."""
    import textwrap
    room = max(MIN_TEXT, columns - width)
    lines = textwrap.wrap(description, room, break_on_hyphens=False) or [""]
    first = f"{name:<{width}}{lines[0]}".rstrip()
    return "\n".join([first] + [" " * width + line for line in lines[1:]])
