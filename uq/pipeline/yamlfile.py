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
* a folder, a device or an endless stream where a file was expected.
"""
import stat
from pathlib import Path

import yaml

from uq.constants import (MAX_BEAMS, MAX_CONFIG_BYTES, MAX_CONFIG_DEPTH, MAX_CONFIG_NODES,
                          MAX_GATES)
from uq.errors import ScenarioError


def read_yaml(path):
    """The YAML document in the file at `path` (plain Python objects)."""
    path = Path(path)
    return parse_yaml(read_text(path), str(path))


def read_text(path, limit=MAX_CONFIG_BYTES):
    """The text of a small configuration file, read with a size limit."""
    try:
        info = path.stat()
        if stat.S_ISDIR(info.st_mode):
            raise ScenarioError(str(path), "", "is a folder; allowed: a YAML file")
        with open(path, "rb") as stream:
            data = stream.read(limit + 1)
    except OSError as error:
        raise ScenarioError(str(path), "", f"cannot read the file ({error.strerror or error})"
                            ) from None
    if len(data) > limit:
        raise ScenarioError(str(path), "", f"larger than {limit // 1024} KiB (or endless); "
                            f"allowed: a YAML file of at most {limit // 1024} KiB")
    return decode(data, str(path))


def decode(data, source):
    """UTF-8 text of `data` (a byte-order mark is allowed), or ScenarioError."""
    if b"\x00" in data:
        raise ScenarioError(source, "", "holds NUL bytes (binary data or UTF-16 text); "
                            "allowed: UTF-8 text")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[:error.start].count(b"\n") + 1
        raise ScenarioError(source, "", f"not UTF-8 text (byte {data[error.start]:#04x} at "
                            f"line {line}; Latin-1 or another encoding?); allowed: UTF-8 "
                            "text") from None


def parse_yaml(text, source):
    """Parse `text`; errors name `source` and the line."""
    loader = _Loader(text)
    loader.source = source
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_expansion(node, source)
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
    """SafeLoader that bounds nesting and refuses repeated keys."""

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

    def construct_mapping(self, node, deep=False):
        seen = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                first = seen.get(key)
            except TypeError:                  # an unhashable key: YAML's own message
                continue
            if first is not None:
                raise ScenarioError(self.source, str(key), f"given twice (lines {first} and "
                                    f"{key_node.start_mark.line + 1}); allowed: each key "
                                    "once in a mapping")
            seen[key] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep)


def _check_expansion(root, source):
    """Refuse a document whose aliases expand to more than MAX_CONFIG_NODES values."""
    sizes, open_nodes = {}, set()

    def size(node):
        if id(node) in open_nodes:
            raise ScenarioError(source, "", f"a YAML alias refers to itself (line "
                                f"{node.start_mark.line + 1}); allowed: aliases of "
                                "finished values")
        if id(node) in sizes:
            return sizes[id(node)]
        open_nodes.add(id(node))
        if isinstance(node, yaml.SequenceNode):
            total = 1 + sum(size(child) for child in node.value)
        elif isinstance(node, yaml.MappingNode):
            total = 1 + sum(size(k) + size(v) for k, v in node.value)
        else:
            total = 1
        open_nodes.discard(id(node))
        sizes[id(node)] = min(total, MAX_CONFIG_NODES + 1)
        return sizes[id(node)]

    if size(root) > MAX_CONFIG_NODES:
        key = _largest_key(root, sizes)
        aliases = _has_alias(root)
        raise ScenarioError(source, key, f"more than {MAX_CONFIG_NODES} values"
                            f"{' once its YAML aliases are expanded' if aliases else ''}; "
                            f"allowed: a scenario's few hundred values"
                            f"{LIST_BOUNDS.get(key, '')}")


#: What the validator allows in the lists a file may make long (said where a file holds
#: more values than MAX_CONFIG_NODES).
LIST_BOUNDS = {"lidar.ranges": f" (at most {MAX_GATES} range gates)",
               "lidar.azimuths": f" (at most {MAX_BEAMS} beams)"}


def _largest_key(root, sizes):
    """Dotted key of the mapping entry that holds most of the document's values: down
    from the root, into the largest value of each mapping ('' if the root is a list)."""
    parts, node = [], root
    while isinstance(node, yaml.MappingNode) and node.value:
        key_node, value = max(node.value, key=lambda kv: sizes.get(id(kv[1]), 1))
        if not isinstance(key_node, yaml.ScalarNode):
            break
        parts.append(str(key_node.value))
        node = value
    return ".".join(parts)


def _has_alias(root):
    """Does a node appear twice in the document (an alias), anywhere below `root`?"""
    seen, stack = set(), [root]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            return True
        seen.add(id(node))
        if isinstance(node, yaml.SequenceNode):
            stack.extend(node.value)
        elif isinstance(node, yaml.MappingNode):
            stack.extend(v for pair in node.value for v in pair)
    return False
