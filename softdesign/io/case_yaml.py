"""Read a case file's YAML within stated bounds: a regular file of at most 1 MB, bounded nesting and aliases.

A case file is a few hundred bytes of keys.  What is not one is refused
before it can hang or fill memory: a FIFO (reading it would wait forever),
``/dev/zero`` or ``/dev/urandom`` (endless), a folder, a file over
:data:`MAX_CASE_BYTES`; YAML nested deeper than :data:`MAX_NESTING` (PyYAML's
composer recurses and would end in a RecursionError) or whose aliases expand
to more than :data:`MAX_NODES` nodes (a "billion laughs" file of 714 bytes
expands to gigabytes), or that holds more values written out (refused from the
event stream, in a second); an alias inside itself; a merge key ``<<`` (it
copies keys unseen, so a key given twice would pass); an integer longer than
:data:`MAX_INTEGER_DIGITS`; and a key given twice in one mapping (YAML would
keep the last silently).  YAML 1.1's base-60 numbers (``1:30`` read as 90)
are kept as text, which the schema then refuses as a number.
"""

from __future__ import annotations

import hashlib
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
#: Most nodes the document may have, written out or with every alias expanded (a case has a few dozen).
MAX_NODES = 100_000
#: Longest integer a case may write, characters: Python refuses to read one of more than 4300 digits, and no case
#: value needs more than a few.
MAX_INTEGER_DIGITS = 100
#: libyaml's parser where PyYAML has it (10 to 100 times faster than the pure-Python one), else that one.
_LOADER: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_INT, _FLOAT, _STR = "tag:yaml.org,2002:int", "tag:yaml.org,2002:float", "tag:yaml.org,2002:str"
_MERGE = "tag:yaml.org,2002:merge"


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
    """What a non-regular file is, for messages ('a folder', 'a FIFO (named pipe)', ...); a symbolic link is named
    only when ``mode`` comes from ``lstat`` (``stat`` follows it)."""
    kinds = [
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ]
    return next((name for test, name in kinds if test(mode)), "not a regular file")


def case_text_record(path: Path, text: str) -> dict[str, str]:
    """The case file's name and the sha256 of its text (as :func:`read_case_text` gives it): what a build records
    to know the file again without validating it."""
    return {"name": path.name, "sha256": hashlib.sha256(text.encode("utf-8")).hexdigest()}


def parse_case_yaml(path: Path, text: str) -> tuple[Any, yaml.Node | None]:
    """The case's data and its node tree (for line numbers), within MAX_NESTING and MAX_NODES, no duplicate keys.

    Raises
    ------
    ConfigError
        Not valid YAML, too deep, too many values (written out or through aliases), an alias that contains
        itself, a merge key, an integer of more than MAX_INTEGER_DIGITS digits, or a key given twice.
    """
    try:
        _check_events(path, text)
        root = yaml.compose(text, Loader=_LOADER)
        if root is not None:
            _check_nodes(path, root)
        data = _LOADER(text).construct_document(root) if root is not None else None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(err, "problem", None) or str(err)
        raise ConfigError(f"{where}: not valid YAML ({problem}); fix the syntax at that line") from None
    return data, root


def _check_events(path: Path, text: str) -> None:
    """Refuse nesting deeper than MAX_NESTING, or more than MAX_NODES values written out, from the event stream.

    The parser does not recurse and holds one event at a time, so this is fast and small whatever the file.
    """
    depth = count = 0
    for event in yaml.parse(text, Loader=_LOADER):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent, yaml.ScalarEvent)):
            count += 1
            if count > MAX_NODES:
                raise ConfigError(
                    f"{_where(path, event)}: the YAML holds more than {MAX_NODES} values (the limit); "
                    "a case file needs a few dozen: the data stay in the files it names"
                )
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_NESTING:
                raise ConfigError(
                    f"{_where(path, event)}: mappings and lists nested more than {MAX_NESTING} deep (the limit); "
                    "a case file is 3 levels deep, see configs/demo.yaml"
                )
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1


def _where(path: Path, item: Any) -> str:
    mark = getattr(item, "start_mark", None)
    return f"{path}:{mark.line + 1}" if mark is not None else str(path)


def _check_nodes(path: Path, root: yaml.Node) -> None:
    """Refuse more than MAX_NODES nodes with aliases expanded, an alias inside itself, and what a scalar must not be.

    An alias is the same node object as its anchor, so each node's expanded
    size is counted once (memoised) and the sum never expands anything.  A
    node met again while its own children are being walked contains itself
    (``a: &a [*a]``), which no case value can.
    """
    sizes: dict[int, int] = {}
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    open_nodes: set[int] = set()
    while stack:  # depth-first, children before their parent, without recursion
        node, done = stack.pop()
        if done:
            open_nodes.discard(id(node))
            sizes[id(node)] = 1 + sum(sizes[id(child)] for child in _children(node))
            if sizes[id(node)] > MAX_NODES:
                raise ConfigError(
                    f"{_where(path, node)}: the YAML expands to more than {MAX_NODES} values (the limit) through its "
                    "aliases (*name); write the values out, a case file needs a few dozen"
                )
            continue
        if id(node) in open_nodes:
            raise ConfigError(f"{_where(path, node)}: an alias (*name) refers to the list or mapping it is inside, "
                              "which would make it contain itself; write the value out")
        if id(node) in sizes:
            continue
        _check_node(path, node)
        open_nodes.add(id(node))
        stack.append((node, True))
        stack.extend((child, False) for child in _children(node))


def _check_node(path: Path, node: yaml.Node) -> None:
    """One node's own rules: a mapping without merge keys or duplicates, a number a case can hold."""
    if isinstance(node, yaml.MappingNode):
        _no_duplicate_keys(path, node)
    elif isinstance(node, yaml.ScalarNode) and node.tag == _INT and len(node.value) > MAX_INTEGER_DIGITS:
        raise ConfigError(f"{_where(path, node)}: an integer of {len(node.value)} characters, more than the "
                          f"{MAX_INTEGER_DIGITS} any case value needs; write the value a case expects")
    elif isinstance(node, yaml.ScalarNode) and node.tag in (_INT, _FLOAT) and ":" in node.value:
        node.tag = _STR  # YAML 1.1 reads 1:30 as 90 (base 60): keep the text, which the schema refuses as a number


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _no_duplicate_keys(path: Path, node: yaml.MappingNode) -> None:
    first: dict[str, int] = {}
    for key, _ in node.value:
        if isinstance(key, yaml.ScalarNode) and key.tag == _MERGE:
            raise ConfigError(
                f"{_where(path, key)}: a merge key (<<) copies keys from elsewhere, where a key given twice would "
                "pass unseen; a case file writes its keys out: replace the << line with the keys it copies"
            )
        if not isinstance(key, yaml.ScalarNode):
            continue
        line = key.start_mark.line + 1
        if key.value in first:
            raise ConfigError(
                f"{path}:{line}: key '{key.value}' is given twice in one mapping (first at line {first[key.value]}); "
                "YAML would keep only the last silently: keep one of the two"
            )
        first[key.value] = line
