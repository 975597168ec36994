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

from uq.constants import MAX_CONFIG_BYTES, MAX_CONFIG_DEPTH, MAX_CONFIG_NODES
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
        _check_expansion(node, source)
        return loader.construct_document(node)
    except ScenarioError:
        raise
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ScenarioError(source, "", f"not valid YAML{where}") from None
    except ValueError as error:             # e.g. an integer of more than 4300 digits
        raise ScenarioError(source, "", f"cannot read a value ({str(error)[:80]}); "
                            "allowed: numbers of at most a few hundred digits") from None
    except RecursionError:
        raise ScenarioError(source, "", f"nested more than {MAX_CONFIG_DEPTH} levels deep; "
                            "allowed: a scenario's few levels") from None
    finally:
        loader.dispose()


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
        raise ScenarioError(source, "", f"expands to more than {MAX_CONFIG_NODES} values "
                            "(YAML aliases); allowed: a scenario's few hundred values")
