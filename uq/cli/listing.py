"""``uq list``: the shipped scenarios, one line each (name and description)."""
import shutil

from uq.cli.common import EXIT_OK, say

#: Narrowest line a description is shortened to [characters] (a terminal that reports a
#: smaller width, or none, still gets a readable line).
MIN_WIDTH = 60


def add_parser(commands):
    listing = commands.add_parser("list", help="the shipped scenarios, one line each (name "
                                  "and description); run one with 'uq run NAME'")
    listing.set_defaults(handler=command)
    return listing


def command(args):
    from uq.pipeline.shipped import describe, shipped_names, shipped_path
    names = shipped_names()
    width = max(len(name) for name in names) + 2
    say(args, "\n".join(scenario_line(name, describe(shipped_path(name)), width,
                                      args.verbose) for name in names))
    return EXIT_OK


def scenario_line(name, description, width, verbose=0):
    """``name  description`` on one line: the description shortened to the terminal's
    width (its whole text with -v)."""
    import textwrap
    room = max(MIN_WIDTH, shutil.get_terminal_size().columns) - width
    text = description if verbose else textwrap.shorten(description, room, placeholder=" ...")
    return f"{name:<{width}}{text}".rstrip()
