"""YAML 1.2 read strictly: ruamel.yaml's safe pure-Python reader (YAML 1.2, its core schema), and the
checks that turn what YAML 1.1 and 1.2 read differently, or what 1.1 lets pass, into one refusal.

What :func:`parse_yaml` refuses, each naming the key path and the line:

* a plain value or key that YAML 1.1 reads otherwise than 1.2 (:data:`READ_OTHERWISE`): a whole
  number with a leading zero (``02500``: 1.1 octal 1344, 1.2 2500; octal is written ``0o2500``),
  a base-60 number (``1:00``: 1.1 60, 1.2 the text ``'1:00'``), yes/no/on/off (1.1 true/false,
  1.2 text); quoted, they are text;
* a key given twice in one mapping, also through merge keys (``<<``): the merged mappings are
  resolved by YAML's rule and a key one of them gives beside the mapping's own, or two give, is
  given twice;
* a key that is not text; a tag beyond YAML 1.2's core types (``!!python/...``, ``!!binary``,
  ``!!timestamp``, ``!custom``); a ``%YAML`` directive of another version;
* more than MAX_VALUES values (mappings, lists and scalars), aliases expanded, nesting beyond
  MAX_DEPTH levels, an alias that contains itself.

Plain values read as YAML 1.2's core schema reads them, with ruamel's extensions that YAML 1.1
reads the same way (``1_000``, ``0b101``); a plain date and ``=`` are text as in YAML 1.2.
"""

from __future__ import annotations

import copy
import functools
import re
import unicodedata
import warnings
from collections.abc import Callable
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.composer import Composer
from ruamel.yaml.error import MarkedYAMLError, YAMLError
from ruamel.yaml.events import CollectionStartEvent, ScalarEvent
from ruamel.yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode
from ruamel.yaml.reader import ReaderError

from ...models.definition.validation import InputError, short

MAX_VALUES = 20_000  # values of a document, aliases expanded (a scene holds about a hundred, the largest
# shipped input, studies/paper/reproduction.yaml, 408)
MAX_DEPTH = 32  # nesting of mappings and lists (a scene has five levels)
CORE = "tag:yaml.org,2002:"
CORE_TAGS = {CORE + name for name in ("str", "int", "float", "bool", "null", "map", "seq")}
MERGE, TEXT = CORE + "merge", CORE + "str"
AS_TEXT = {CORE + "timestamp", CORE + "value"}  # plain scalars ruamel resolves beyond YAML 1.2's core schema
LEADING_ZERO = re.compile(r"^[-+]?0[0-9_]+$")
BASE_60 = re.compile(r"^[-+]?(?:[1-9][0-9_]*(?::[0-5]?[0-9])+|[0-9][0-9_]*(?::[0-5]?[0-9])+\.[0-9_]*)$")
BOOLEAN_11 = {word: value for words, value in (("yes on", True), ("no off", False))
              for word in words.split() for word in (word, word.capitalize(), word.upper())}


class Refused(YAMLError):
    """Valid YAML that the strict reader refuses: the key path, the line, and why."""

    def __init__(self, path: str, line: int, message: str) -> None:
        super().__init__(message)
        self.path, self.line, self.message = path, line, message


class _CountingComposer(Composer):
    """ruamel's composer that stops at MAX_VALUES values (before the rest is read) and remembers the
    nodes of explicit tags."""

    def __init__(self, loader: Any = None) -> None:
        super().__init__(loader)
        self.composed = 0
        self.explicit: set[int] = set()
        self.kept: list[Node] = []  # the explicitly tagged nodes, alive while their ids are used

    def compose_node(self, parent: Any, index: Any) -> Any:
        event = self.parser.peek_event()
        tagged = isinstance(event, (ScalarEvent, CollectionStartEvent)) and event.ctag is not None \
            and str(event.ctag) != "!"
        if isinstance(event, (ScalarEvent, CollectionStartEvent)):
            self.composed += 1
            if self.composed > MAX_VALUES:
                raise Refused("", event.start_mark.line + 1, f"more than {MAX_VALUES} values; an input holds at most "
                              f"{MAX_VALUES} (a scene about a hundred)")
        node = super().compose_node(parent, index)
        if tagged:
            self.explicit.add(id(node))
            self.kept.append(node)
        return node


def read_otherwise(node: ScalarNode, as_key: bool = False) -> str | None:
    """Why YAML 1.1 reads the plain scalar ``node`` (a value, or a key: ``as_key``) otherwise than YAML
    1.2 (None: the same)."""
    text = node.value
    if node.style is not None or node.tag not in CORE_TAGS:
        return None
    if LEADING_ZERO.match(text):
        digits = text.replace("_", "").lstrip("+-")
        sign = "-" if text.startswith("-") else ""
        as_11 = f"the octal {sign}{int(digits, 8)}" if set(digits) <= set("01234567") else "text"
        octal = f" (or {sign}0o{digits.lstrip('0') or '0'} for the octal number)" if as_11 != "text" else ""
        return (f"a whole number with a leading zero: YAML 1.2 reads {int(text.replace('_', ''))}, YAML 1.1 {as_11}; "
                f"write {sign}{int(digits)}{octal}")
    if BASE_60.match(text):
        sign, parts = (-1 if text.startswith("-") else 1), text.lstrip("+-").replace("_", "").split(":")
        value = 0.0
        for part in parts:
            value = value * 60 + float(part)
        shown = f"{sign * value:g}"
        return (f"YAML 1.2 reads the text {text!r}, YAML 1.1 the base-60 number {shown}; write the number "
                f"({shown}), or quote it for text")
    if text in BOOLEAN_11:
        hint = "quote it" if as_key else "write true or false, or quote it for text"
        return f"YAML 1.2 reads the text {text!r}, YAML 1.1 {str(BOOLEAN_11[text]).lower()}; {hint}"
    return None


def _join(parent: str, key: Any) -> str:
    return f"{parent}.{key}" if parent else str(key)


def _line(node: Node) -> int:
    return node.start_mark.line + 1


def _merged(value: Node, path: str) -> list[MappingNode]:
    """The mappings a merge key's value gives (a mapping, or a list of them), in order."""
    if isinstance(value, MappingNode):
        return [value]
    if isinstance(value, SequenceNode) and all(isinstance(item, MappingNode) for item in value.value):
        return list(value.value)
    raise Refused(_join(path, "<<"), _line(value), "a merge key '<<' takes a mapping or a list of mappings")


def _keys(node: MappingNode, path: str, merging: frozenset[int] = frozenset()) -> dict[str, tuple[int, int | None]]:
    """Every key of ``node`` after its merge keys are resolved: the line that gives it and the line of
    the merge key '<<' that brings it (None: the mapping's own); Refused for a key given twice (module
    doc). ``merging``: the mappings being merged into it (one that merges itself is a recursive alias)."""
    if id(node) in merging:
        raise Refused(path, _line(node), "a recursive alias (an anchor that contains itself)")
    keys: dict[str, tuple[int, int | None]] = {}

    def add(key: str, line: int, merge: int | None) -> None:
        if key in keys:
            first, first_merge = keys[key]
            what = f"first at line {first}" if merge is None and first_merge is None else \
                f"given at line {first} and by the merge key '<<' at line {merge} (from line {line})" \
                if first_merge is None else \
                f"given by two mappings the merge key '<<' at line {merge} merges (lines {first} and {line})"
            raise Refused(_join(path, key), merge or line, f"duplicate key, {what}; a key may appear once in a "
                          "mapping, merge keys included")
        keys[key] = (line, merge)

    for key_node, _ in node.value:
        if key_node.tag != MERGE:
            add(str(key_node.value), _line(key_node), None)
    for key_node, value in node.value:
        if key_node.tag == MERGE:
            for merged in _merged(value, path):
                for key, (line, _) in _keys(merged, path, merging | {id(node)}).items():
                    add(key, line, _line(key_node))
    return keys


def check_nodes(root: Node, explicit: set[int], resolve: Callable[[str], str]) -> None:
    """Refused for the first problem of the module doc below ``root`` (tags of the ids in
    ``explicit`` were written in the file: such a value is what its tag says, and must read as it,
    ``resolve`` giving the tag its text reads as); plain dates and '=' become text."""
    sizes: dict[int, int] = {}  # id -> values below the node, aliases expanded
    stack: list[tuple[Node, str, int, bool]] = [(root, "", 1, False)]
    open_nodes: set[int] = set()
    while stack:
        node, path, depth, done = stack.pop()
        children = [value for _, value in node.value] if isinstance(node, MappingNode) \
            else node.value if isinstance(node, SequenceNode) else []
        if done:  # a mapping's keys are one value each (checked: text)
            open_nodes.discard(id(node))
            keys = len(node.value) if isinstance(node, MappingNode) else 0
            sizes[id(node)] = 1 + keys + sum(sizes[id(child)] for child in children)
            if sizes[id(node)] > MAX_VALUES:
                raise Refused(path, _line(node), f"aliases expand to more than {MAX_VALUES} values; write the values "
                              "out")
            continue
        if id(node) in open_nodes:
            raise Refused(path, _line(node), "a recursive alias (an anchor that contains itself)")
        if id(node) in sizes:
            continue
        if depth > MAX_DEPTH:
            raise Refused(path, _line(node), f"nested more than {MAX_DEPTH} levels deep")
        _check_tag(node, path, explicit)
        if isinstance(node, ScalarNode):
            why = read_otherwise(node) if id(node) not in explicit else _not_as_tagged(node, resolve)
            if why:
                raise Refused(path, _line(node), f"{node.value}: {why}")
            if node.tag in AS_TEXT and id(node) not in explicit:
                node.tag = TEXT
        open_nodes.add(id(node))
        stack.append((node, path, depth, True))
        if isinstance(node, MappingNode):
            _keys(node, path)
            for key, value in node.value:
                if key.tag == MERGE:
                    stack.append((value, path, depth + 1, False))
                    continue
                _check_key(key, path, key_tag_written=id(key) in explicit)
                stack.append((value, _join(path, key.value), depth + 1, False))
        else:
            stack += [(child, _join(path, i), depth + 1, False) for i, child in enumerate(children)]


def _check_tag(node: Node, path: str, explicit: set[int]) -> None:
    if node.tag in CORE_TAGS or node.tag == MERGE or (node.tag in AS_TEXT and id(node) not in explicit):
        return
    shown = node.tag.replace(CORE, "!!")
    raise Refused(path, _line(node), f"the tag {shown}: not allowed; an input holds YAML 1.2's core types only "
                  "(text, numbers, true/false, null, mappings and lists)")


def _not_as_tagged(node: ScalarNode, resolve: Callable[[str], str]) -> str | None:
    """Why a value of a written core tag (``!!int 1.5``) does not read as its tag (None: it does; text
    and null always do)."""
    read = resolve(node.value)
    if node.tag in (TEXT, CORE + "null") or node.tag not in CORE_TAGS or read == node.tag or \
            (node.tag == CORE + "float" and read == CORE + "int"):  # (!!float 3 is 3.0)
        return None
    return f"not a value of its tag {node.tag.replace(CORE, '!!')}"


def _check_key(key: Node, path: str, key_tag_written: bool = False) -> None:
    """Refused unless ``key`` is text that YAML 1.1 reads the same way (or text by its written tag)."""
    if not isinstance(key, ScalarNode):
        shown = "a mapping" if isinstance(key, MappingNode) else "a list"
        raise Refused(_join(path, "?"), _line(key), f"key {shown} is not text; a key is a name")
    where = _join(path, key.value)
    why = None if key_tag_written else read_otherwise(key, as_key=True)
    if why:
        raise Refused(where, _line(key), f"the key {key.value}: {why}")
    if key.tag != TEXT:
        raise Refused(where, _line(key), f"key {short(key.value)} is not text; quote it (YAML reads numbers, "
                      "true/false and null as such)")


def _hidden_character(text: str) -> str | None:
    """The first control character (but tab and newline) or invisible format character (direction
    marks, zero-width characters) in ``text``."""
    return next((c for c in text if c not in "\t\n" and unicodedata.category(c) in ("Cc", "Cf")), None)


def _hidden_text(data: Any) -> str | None:
    """'<key.path>: <value>: ...' for the first key or text value below ``data`` that holds a hidden
    character (:func:`_hidden_character`), None if there is none."""
    stack: list[tuple[Any, str]] = [(data, "")]
    while stack:
        value, where = stack.pop()
        if isinstance(value, dict):
            stack += [(key, where) for key in value] + [(item, _join(where, key)) for key, item in value.items()]
        elif isinstance(value, list):
            stack += [(item, _join(where, i)) for i, item in enumerate(value)]
        elif isinstance(value, str) and (hidden := _hidden_character(value)) is not None:
            name = unicodedata.name(hidden, "")
            return (f"{where or '(top level)'}: {short(value)}: holds the control or invisible character "
                    f"U+{ord(hidden):04X}{f' ({name})' if name else ''}; text here is printable characters only")
    return None


def _document(text: str) -> Any:
    """The document of ``text`` composed, checked (:func:`check_nodes`) and constructed; None when empty."""
    reader = YAML(typ="safe", pure=True)
    reader.Composer = _CountingComposer
    reader.max_depth = MAX_DEPTH + 1
    node = reader.compose(text)
    if node is None:
        return None
    declared = reader.resolver.processing_version
    if declared != (1, 2):
        raise Refused("", 1, f"the directive %YAML {'.'.join(map(str, declared))}: rpdrill reads YAML 1.2; remove "
                      "the %YAML line")
    check_nodes(node, reader.composer.explicit, lambda text: reader.resolver.resolve(ScalarNode, text, (True, False)))
    return reader.constructor.construct_document(node)


@functools.lru_cache(maxsize=32)
def _kept_document(text: str) -> Any:
    """:func:`_document` of ``text``, kept for the next read of the same text (the caller takes a copy): a
    process that reads one file many times (a test suite's scenes: about 1 900 reads, 5 ms each for
    paper_base) parses it once. A refused text is not kept: it is refused again."""
    return _document(text)


def parse_yaml(text: str, source: str) -> dict[str, Any]:
    """The top-level mapping of YAML ``text`` read strictly (module doc); InputError naming
    ``source``, the key path and the line otherwise."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # ruamel's warnings (a reused anchor) are not the user's problem
            data = copy.deepcopy(_kept_document(text))
    except Refused as err:
        where = f"{err.path} (line {err.line})" if err.path else f"line {err.line}"
        raise InputError(f"{source}: {where}: {err.message}") from None
    except ReaderError as err:
        line = text[:err.position].count("\n") + 1
        character = err.character if isinstance(err.character, int) else ord(err.character)
        raise InputError(f"{source}: line {line}: character U+{character:04X} is not allowed in YAML text "
                         "(a control character)") from None
    except MarkedYAMLError as err:
        if "maximum depth" in str(err.problem):
            line = err.problem_mark.line + 1 if err.problem_mark else "?"
            raise InputError(f"{source}: line {line}: nested more than {MAX_DEPTH} levels deep") from None
        mark = err.problem_mark or err.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem, context = (err.problem or "").strip(), (err.context or "").strip()
        said = f"{context}, {problem}" if context.startswith("expected") and problem else \
            f"{problem} ({context})" if context and problem else problem or context
        raise InputError(f"{source}: {where}not valid YAML: {said}") from None
    except AssertionError as err:  # ruamel's check of a %YAML directive of another version (1.3)
        raise InputError(f"{source}: line 1: not valid YAML: a %YAML directive of another version ({err}); rpdrill "
                         "reads YAML 1.2: remove the %YAML line") from None
    except (YAMLError, ValueError) as err:
        raise InputError(f"{source}: not valid YAML: {short(str(err).splitlines()[0] if str(err) else type(err))}") \
            from None
    except RecursionError:
        raise InputError(f"{source}: nested too deeply to read; at most {MAX_DEPTH} levels") from None
    if data is None:
        raise InputError(f"{source}: the file is empty; expected a mapping of keys")
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected a mapping of keys at the top level, found "
                         f"{'a list' if isinstance(data, list) else short(data)}")
    hidden = _hidden_text(data)
    if hidden:
        raise InputError(f"{source}: {hidden}")
    return data
