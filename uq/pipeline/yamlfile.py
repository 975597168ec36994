"""Reading YAML configuration files safely: bounded in size, depth and expansion, strict
about encoding and repeated keys. No physics.

A scenario file is small. Whatever a file holds, reading it costs at most
:data:`~uq.constants.MAX_CONFIG_BYTES` bytes, :data:`~uq.constants.MAX_CONFIG_DEPTH`
levels of nesting and :data:`~uq.constants.MAX_CONFIG_NODES` values once aliases are
expanded (a "billion laughs" alias bomb is refused before it is built). Every problem is
an :class:`~uq.errors.ScenarioError` naming the file, the line and what is allowed:

* a file that is not UTF-8 text (binary data, Latin-1, UTF-16);
* a key given twice in one mapping (YAML would silently keep the last: a repeated ``ins``
  section would drop the first one's errors);
* a folder, a device, a named pipe or an endless stream where a file was expected
  (:mod:`uq.pipeline.inputfile`).
"""
from pathlib import Path

import yaml

from uq.constants import (MAX_BEAMS, MAX_CONFIG_BYTES, MAX_CONFIG_DEPTH, MAX_CONFIG_NODES,
                          MAX_GATES)
from uq.errors import ScenarioError
from uq.pipeline.inputfile import decode, read_bytes


def read_yaml(path, kind="a YAML file"):
    """The YAML document in the file at `path` (plain Python objects); `kind` names the
    file in messages (``"a YAML scenario"``)."""
    path = Path(path)
    return parse_yaml(read_text(path, kind=kind), str(path))


def read_text(path, limit=MAX_CONFIG_BYTES, kind="a YAML file"):
    """The UTF-8 text of a small configuration file: a regular file, read without
    blocking and with a size limit (:func:`uq.pipeline.inputfile.read_bytes`)."""
    return decode(read_bytes(path, limit, kind), str(path))


def parse_yaml(text, source):
    """Parse `text`; errors name `source` and the line."""
    loader = _Loader(text)
    loader.source = source
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_nodes(node, source)
        return loader.construct_document(node)
    except ScenarioError:
        raise
    except yaml.YAMLError as error:
        raise ScenarioError(source, "", f"not valid YAML{_where(error, text)}") from None
    except ValueError as error:             # e.g. an integer of more than 4300 digits
        raise ScenarioError(source, "", f"cannot read a value ({str(error)[:80]}); "
                            "allowed: numbers of at most a few hundred digits") from None
    except RecursionError:
        raise ScenarioError(source, "", f"nested more than {MAX_CONFIG_DEPTH} levels deep; "
                            "allowed: a scenario's few levels") from None
    finally:
        loader.dispose()


#: Characters of a line shown around the place of a YAML syntax error.
SHOWN_LINE = 60


def _where(error, text):
    """`` at line L, column C: problem (here: "text ^text")`` for a YAML error with a
    place: the line as written, a caret where the parser stopped (one line)."""
    mark = getattr(error, "problem_mark", None)
    if mark is None:
        return ""
    lines = text.splitlines()
    line = lines[mark.line] if mark.line < len(lines) else ""
    first = max(0, mark.column - SHOWN_LINE // 2)
    shown = line[first:mark.column] + "^" + line[mark.column:first + SHOWN_LINE]
    problem = getattr(error, "problem", None)
    return (f" at line {mark.line + 1}, column {mark.column + 1}"
            f"{': ' + problem if problem else ''} (here: {shown.strip()!r})")


class _Loader(yaml.SafeLoader):
    """SafeLoader that bounds nesting (repeated keys, tags and aliases: _check_nodes)."""

    depth = 0

    def compose_node(self, parent, index):
        self.depth += 1
        try:
            if self.depth > MAX_CONFIG_DEPTH:
                mark = self.peek_event().start_mark
                raise ScenarioError(self.source, "", f"nested more than {MAX_CONFIG_DEPTH} "
                                    f"levels deep at line {mark.line + 1}; allowed: a "
                                    "scenario's few levels")
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


def _check_nodes(root, source):
    """Check the composed document before anything is built: every key once per mapping,
    only plain YAML tags, and at most MAX_CONFIG_NODES values once aliases are expanded.
    Each problem names the dotted key where it sits (shared nodes are visited once)."""
    sizes, open_nodes, aliased = {}, set(), []

    def size(node, path):
        if id(node) in open_nodes:
            _fail(source, path, f"a YAML alias refers to itself (line "
                  f"{node.start_mark.line + 1}); allowed: aliases of finished values")
        if id(node) in sizes:
            aliased.append(path)                 # a node seen twice: an alias
            return sizes[id(node)]
        open_nodes.add(id(node))
        _check_tag(node, path, source)
        if isinstance(node, yaml.SequenceNode):
            total = 1 + sum(size(child, f"{path}[{i}]") for i, child in enumerate(node.value))
        elif isinstance(node, yaml.MappingNode):
            _check_repeats(node, path, source)
            total = 1 + sum(size(k, path) + size(v, _join(path, k)) for k, v in node.value)
        else:
            total = 1
        open_nodes.discard(id(node))
        if total > MAX_CONFIG_NODES:
            _fail(source, path, f"more than {MAX_CONFIG_NODES} values"
                  f"{' once its YAML aliases are expanded' if aliased else ''}; allowed: "
                  f"a scenario's few hundred values{LIST_BOUNDS.get(path, '')}")
        sizes[id(node)] = total
        return total

    size(root, "")


def _join(path, key_node):
    """The dotted key of a mapping's value (a key that is not text is shown as YAML)."""
    key = key_node.value if isinstance(key_node, yaml.ScalarNode) else "?"
    return f"{path}.{key}" if path else str(key)


def _check_repeats(node, path, source):
    """Refuse a key given twice in one mapping (YAML would keep the last silently)."""
    seen = {}
    for key_node, _ in node.value:
        if not isinstance(key_node, yaml.ScalarNode):
            continue
        mark = key_node.start_mark
        first = seen.setdefault((key_node.tag, key_node.value), mark)
        if first is mark:
            continue
        where = f"lines {first.line + 1} and {mark.line + 1}" if first.line != mark.line \
            else f"line {mark.line + 1}, columns {first.column + 1} and {mark.column + 1}"
        _fail(source, _join(path, key_node), f"given twice ({where}); allowed: each key "
              "once in a mapping")


def _check_tag(node, path, source):
    """Refuse an explicit tag PyYAML's safe loader cannot build (``!!python/...``)."""
    if node.tag not in _Loader.yaml_constructors and node.tag != _MERGE:
        tag = node.tag.replace(_STANDARD, "!!")
        _fail(source, path, f"the YAML tag {tag!r} (line {node.start_mark.line + 1}) is "
              "not allowed; allowed: plain values (numbers, text, true/false, lists, "
              "mappings)")


#: Prefix of YAML's standard tags (written ``!!`` in a file), and the merge key ``<<``.
_STANDARD = "tag:yaml.org,2002:"
_MERGE = _STANDARD + "merge"


def _fail(source, path, problem):
    raise ScenarioError(source, path or "", problem)


#: What the validator allows in the lists a file may make long (said where a file holds
#: more values than MAX_CONFIG_NODES).
LIST_BOUNDS = {"lidar.ranges": f" (at most {MAX_GATES} range gates)",
               "lidar.azimuths": f" (at most {MAX_BEAMS} beams)"}
