"""Read a case file's YAML within stated bounds: a regular file of at most 1 MB, bounded nesting and aliases.

A case file is a few hundred bytes of keys.  What is not one is refused
before it can hang or fill memory: a FIFO (reading it would wait forever),
``/dev/zero`` or ``/dev/urandom`` (endless), a folder, a file over
:data:`MAX_CASE_BYTES`; YAML nested deeper than :data:`MAX_NESTING` (PyYAML's
composer recurses and would end in a RecursionError) or whose aliases expand
to more than :data:`MAX_NODES` nodes (a "billion laughs" file of 714 bytes
expands to gigabytes); and a key given twice in one mapping (YAML would keep
the last silently).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Any

import yaml

from softdesign.errors import ConfigError

#: A case file is at most this many bytes (1 MB): the largest real case is under 4 kB.
MAX_CASE_BYTES = 1_000_000
#: Deepest nesting of mappings and lists: a case is 3 levels deep (export.q is a list in a mapping in the file).
MAX_NESTING = 32
#: Most nodes the document may have with every alias expanded (a 1 MB file of plain keys has fewer).
MAX_NODES = 100_000


def read_case_text(path: Path) -> str:
    """The text of the case file ``path``, checked to be a regular file of at most MAX_CASE_BYTES.

    The file is opened without blocking (a FIFO cannot hang the read) and
    checked with ``fstat`` on the open descriptor, so what is checked is what is read.

    Raises
    ------
    ConfigError
        Missing, not a regular file, too large, unreadable, or not UTF-8.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise ConfigError(f"{path}: case file not found; check the path") from None
    except OSError as err:
        raise ConfigError(f"{path}: cannot open the case file ({err.strerror}); check its permissions") from None
    try:
        data = _read_regular(path, fd)
    finally:
        os.close(fd)
    if len(data) > MAX_CASE_BYTES:  # the file grew after fstat
        raise ConfigError(f"{path}: the case file is more than the limit of {MAX_CASE_BYTES} bytes (1 MB)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise ConfigError(
            f"{path}: the case file is not UTF-8 text (byte {err.start}: {data[err.start:err.start + 1]!r}); "
            "save it as UTF-8 YAML"
        ) from None


def _read_regular(path: Path, fd: int) -> bytes:
    """At most MAX_CASE_BYTES + 1 bytes of the open ``fd``, after checking it is a regular file of at most that size."""
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        raise ConfigError(
            f"{path}: is {file_kind(info.st_mode)}, not a regular file; expected a YAML case file "
            "(e.g. configs/demo.yaml)"
        )
    if info.st_size > MAX_CASE_BYTES:
        raise ConfigError(
            f"{path}: the case file is {info.st_size} bytes, more than the limit of {MAX_CASE_BYTES} bytes "
            "(1 MB); a case file holds keys and paths, the data stay in the files it names"
        )
    try:
        return os.read(fd, MAX_CASE_BYTES + 1)
    except OSError as err:
        raise ConfigError(f"{path}: cannot read the case file ({err.strerror})") from None


def file_kind(mode: int) -> str:
    """What a non-regular file is, for messages ('a folder', 'a FIFO (named pipe)', ...)."""
    kinds = [
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ]
    return next((name for test, name in kinds if test(mode)), "not a regular file")


def parse_case_yaml(path: Path, text: str) -> tuple[Any, yaml.Node | None]:
    """The case's data and its node tree (for line numbers), within MAX_NESTING and MAX_NODES, no duplicate keys.

    Raises
    ------
    ConfigError
        Not valid YAML, too deep, too many nodes after alias expansion, or a key given twice.
    """
    try:
        _check_nesting(path, text)
        root = yaml.compose(text, Loader=yaml.SafeLoader)
        if root is not None:
            _check_nodes(path, root)
        data = yaml.SafeLoader(text).construct_document(root) if root is not None else None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(err, "problem", None) or str(err)
        raise ConfigError(f"{where}: not valid YAML ({problem}); fix the syntax at that line") from None
    return data, root


def _check_nesting(path: Path, text: str) -> None:
    """Refuse nesting deeper than MAX_NESTING from the event stream (the parser does not recurse)."""
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_NESTING:
                where = f"{path}:{event.start_mark.line + 1}" if event.start_mark is not None else str(path)
                raise ConfigError(
                    f"{where}: mappings and lists nested more than {MAX_NESTING} deep (the limit); "
                    "a case file is 3 levels deep, see configs/demo.yaml"
                )
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1


def _check_nodes(path: Path, root: yaml.Node) -> None:
    """Refuse more than MAX_NODES nodes with aliases expanded, and a key given twice in one mapping.

    An alias is the same node object as its anchor, so each node's expanded
    size is counted once (memoised) and the sum never expands anything.
    """
    sizes: dict[int, int] = {}
    order: list[yaml.Node] = []
    stack: list[yaml.Node] = [root]
    seen: set[int] = set()
    while stack:  # post-order without recursion: children before their parent
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        order.append(node)
        stack.extend(_children(node))
    for node in reversed(order):
        if isinstance(node, yaml.MappingNode):
            _no_duplicate_keys(path, node)
        sizes[id(node)] = 1 + sum(sizes[id(child)] for child in _children(node))
        if sizes[id(node)] > MAX_NODES:
            line = node.start_mark.line + 1
            raise ConfigError(
                f"{path}:{line}: the YAML expands to more than {MAX_NODES} values (the limit) through its aliases "
                "(*name); write the values out, a case file needs a few dozen"
            )


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _no_duplicate_keys(path: Path, node: yaml.MappingNode) -> None:
    first: dict[str, int] = {}
    for key, _ in node.value:
        if not isinstance(key, yaml.ScalarNode) or key.tag == "tag:yaml.org,2002:merge":
            continue
        line = key.start_mark.line + 1
        if key.value in first:
            raise ConfigError(
                f"{path}:{line}: key '{key.value}' is given twice in one mapping (first at line {first[key.value]}); "
                "YAML would keep only the last silently: keep one of the two"
            )
        first[key.value] = line
