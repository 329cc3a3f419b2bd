"""Safe XML reading shared by the URDF and MJCF loaders.

Parsing forbids DTDs, entities and external references (defusedxml), bounds the nesting
depth and the size of the input, and records the line of every element so that every error
can name where it is. A byte-order mark or whitespace before ``<?xml ...?>`` is accepted, as
the major loaders accept it.

:func:`parse_lazy_lines` (the URDF loader's) reads a text without ``<!DOCTYPE`` with the C tree
builder of ``xml.etree`` and finds the lines only when a message needs them; any other text,
and any failure, goes through :func:`parse`: the same elements, attributes, errors and refusals
(the fast tree also keeps element text, which the loaders do not read).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
from defusedxml import DefusedXmlException, DTDForbidden
from defusedxml.ElementTree import DefusedXMLParser, ParseError
from xml.etree.ElementTree import Element, TreeBuilder, XMLParser
from xml.parsers.expat import ExpatError, errors

from ..errors import ModelError

MAX_DEPTH = 64
# Texts up to this many characters may take the fast path of :func:`parse_lazy_lines`.
FAST_PARSE_MAX_CHARS = 8 * 1024 * 1024


class LineParser(DefusedXMLParser):
    """DefusedXMLParser (its handlers refuse DTDs, entities and external references) whose
    element handlers build the tree directly, record the line of every element and bound the
    nesting (a several-fold faster than ElementTree's Python-level handlers). Text content
    is not kept: robot descriptions are read from attributes."""

    def __init__(self):
        super().__init__(forbid_dtd=True, forbid_entities=True, forbid_external=True)
        self.lines: dict[int, int] = {}
        self.root = None
        self._stack: list = []
        expat = self.parser
        expat.ordered_attributes = False
        expat.StartElementHandler = self._element_start
        expat.EndElementHandler = self._element_end
        expat.CharacterDataHandler = None
        expat.DefaultHandlerExpand = None  # ElementTree's, for text and doctypes we do not keep

    def _element_start(self, tag, attrib):
        # expat writes a namespaced name as "uri}local"; ElementTree's form is "{uri}local"
        if "}" in tag:
            tag = "{" + tag
        if attrib and any("}" in k for k in attrib):
            attrib = {("{" + k if "}" in k else k): v for k, v in attrib.items()}
        stack = self._stack
        line = self.parser.CurrentLineNumber
        if len(stack) >= MAX_DEPTH:
            raise ModelError(f"<{tag}> (line {line}): elements nested deeper than {MAX_DEPTH} levels")
        elem = Element(tag, attrib)
        if stack:
            stack[-1].append(elem)
        elif self.root is None:
            self.root = elem
        stack.append(elem)
        self.lines[id(elem)] = line

    def _element_end(self, tag):
        self._stack.pop()

    def parse_text(self, text: str):
        """The root element of ``text``; expat's errors as ``ParseError`` with a position."""
        try:
            self.parser.Parse(text, True)
        except ExpatError as e:
            err = ParseError(f"{errors.messages[e.code]}: line {e.lineno}, column {e.offset}")
            err.code, err.position = e.code, (e.lineno, e.offset)
            raise err from None
        return self.root


def is_xml_text(source) -> bool:
    """True when ``source`` is XML text rather than a path (its first character is ``<``)."""
    return isinstance(source, str) and source.lstrip("\ufeff \t\r\n").startswith("<")


def read_source(source, kind: str, max_bytes: int) -> tuple[str, str]:
    """``(xml_text, name)`` from a path or an XML string; ``kind`` ("URDF", "MJCF") names
    the format in errors. The text has a leading byte-order mark and whitespace removed."""
    if isinstance(source, str) and not source.strip():
        raise ModelError(f"<string>: empty input: expected a {kind} path or XML text")
    if isinstance(source, (str, os.PathLike)) and not is_xml_text(source):
        path = Path(source)
        try:
            is_file = path.is_file()
            size = path.stat().st_size if is_file else 0
        except (OSError, ValueError) as e:
            raise ModelError(f"{path}: cannot read {kind} file ({getattr(e, 'strerror', None) or e})") from None
        if not is_file:
            reason = "not a regular file" if path.exists() else "no such file"
            raise ModelError(f"{path}: cannot read {kind} file ({reason})")
        if size > max_bytes:
            raise ModelError(f"{path}: file of {size} bytes exceeds the limit of {max_bytes} bytes")
        try:
            text = path.read_bytes().decode("utf-8")
        except OSError as e:
            raise ModelError(f"{path}: cannot read {kind} file ({e.strerror or e})") from None
        except UnicodeDecodeError as e:
            raise ModelError(f"{path}: not UTF-8 text ({e})") from None
        return _strip_lead(text), str(path)
    if isinstance(source, bytes):
        source = source.decode("utf-8", errors="strict")
    if not isinstance(source, str):
        raise TypeError(f"expected a {kind} path or an XML string, got {type(source).__name__}")
    if len(source) > max_bytes:
        raise ModelError(f"<string>: XML of {len(source)} characters exceeds the limit of {max_bytes}")
    return _strip_lead(source), "<string>"


def _strip_lead(text: str) -> str:
    """Drop a byte-order mark, and blank out an XML declaration preceded by whitespace (expat
    accepts a declaration only at the very start; the text is already decoded). Line numbers
    are kept."""
    body = text.lstrip("\ufeff")
    lead = len(body) - len(body.lstrip(" \t\r\n"))
    if lead and body.startswith("<?xml", lead):
        end = body.find("?>", lead)
        if end > 0:
            body = body[:lead] + " " * (end + 2 - lead) + body[end + 2:]
    return body


def source_line(text: str, line) -> str:
    """The stripped text of a 1-based line (shortened), to show where the XML breaks."""
    lines = text.splitlines()
    if not isinstance(line, int) or not 1 <= line <= len(lines):
        return ""
    snippet = lines[line - 1].strip()
    return f": {snippet[:80] + ('...' if len(snippet) > 80 else '')!r}"


def parse(text: str, name: str):
    """``(root element, {id(element): line})``; every failure is a :class:`ModelError`.

    Namespaces: elements in the root element's namespace (a default ``xmlns`` on ``<robot>``)
    lose it (``joint``), elements of other namespaces keep it (``{uri}joint``, extension
    elements such as ``<drake:joint>``, which loaders ignore). A prefix used without its
    ``xmlns:prefix`` declaration, which major loaders accept, is declared as
    ``urn:undeclared:prefix``.
    """
    try:
        root, lines = _parse(text, name)
    except _UnboundPrefix:
        try:
            root, lines = _parse(_declare_prefixes(text), name)
        except _UnboundPrefix:
            raise ModelError(f"{name}: malformed XML (a namespace prefix that cannot be declared)") from None
    _strip_default_namespace(root)
    return root, lines


def parse_lazy_lines(text: str, name: str):
    """:func:`parse`, about twice as fast: ``(root element, lines)``, where ``lines`` maps
    ``id(element)`` to its line through ``lines.get`` and finds the lines only when first asked
    (an error message), by parsing the text again with :func:`parse`.

    The fast path is the C tree builder of ``xml.etree`` (expat, as :func:`parse`), taken when
    the text has no ``<!DOCTYPE`` (so expat sees no DTD, no entity declaration and no external
    reference: an entity other than the five predefined ones is an expat error) and is at most
    ``FAST_PARSE_MAX_CHARS`` long; its tree is checked against ``MAX_DEPTH``. Any failure
    (malformed XML, an undeclared prefix, a tree too deep) and every other text go through
    :func:`parse`, which gives the same tree or the same error as before.
    """
    if len(text) <= FAST_PARSE_MAX_CHARS and "<!DOCTYPE" not in text:
        try:
            parser = XMLParser(target=TreeBuilder())
            parser.feed(text)
            root = parser.close()
        except Exception:  # the checked parser below says what is wrong
            root = None
        if root is not None and _depth_within(root, MAX_DEPTH):
            _strip_default_namespace(root)
            return root, _LazyLines(text, name, root)
    return parse(text, name)


def _depth_within(root, depth: int) -> bool:
    """Whether no element lies deeper than ``depth`` levels (the root is level 1)."""
    level = [root]
    for _ in range(depth):
        level = [c for e in level for c in e]
        if not level:
            return True
    return False


class _LazyLines:
    """``{id(element): line}`` of a tree parsed without lines, found on the first ``get`` by
    parsing the text again with :func:`parse` (the two trees hold the same elements in the same
    document order)."""

    __slots__ = ("_text", "_name", "_root", "_lines")

    def __init__(self, text: str, name: str, root):
        self._text, self._name, self._root, self._lines = text, name, root, None

    def get(self, key, default=None):
        if self._lines is None:
            root, lines = parse(self._text, self._name)
            self._lines = {id(a): lines[id(b)] for a, b in zip(self._root.iter(), root.iter())}
            self._text = self._root = None
        return self._lines.get(key, default)


class _UnboundPrefix(Exception):
    pass


_PREFIX = re.compile(r"<\s*/?\s*([A-Za-z_][\w.-]*):|\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=")
_ROOT_START = re.compile(r"<\s*(?![?!])[^\s/>]+")


def _declare_prefixes(text: str) -> str:
    """``text`` with every used, undeclared namespace prefix declared on the root element (on
    the root's own line, so line numbers hold)."""
    used = {m.group(1) or m.group(2) for m in _PREFIX.finditer(text)} - {"xml", "xmlns"}
    declared = set(re.findall(r"xmlns:([A-Za-z_][\w.-]*)\s*=", text))
    missing = sorted(used - declared)
    m = _ROOT_START.search(text)
    if not missing or m is None:
        return text
    decl = "".join(f' xmlns:{p}="urn:undeclared:{p}"' for p in missing)
    return text[: m.end()] + decl + text[m.end():]


def _strip_default_namespace(root) -> None:
    if not (isinstance(root.tag, str) and root.tag.startswith("{")):
        return
    prefix = root.tag[: root.tag.index("}") + 1]
    for elem in root.iter():
        if isinstance(elem.tag, str) and elem.tag.startswith(prefix):
            elem.tag = elem.tag[len(prefix):]


def _parse(text: str, name: str):
    parser = LineParser()
    try:
        root = parser.parse_text(text)
    except ParseError as e:
        if "unbound prefix" in str(e):
            raise _UnboundPrefix() from None
        line = e.position[0] if getattr(e, "position", None) else "?"
        raise ModelError(f"{name}: line {line}{source_line(text, line)}: malformed XML ({e})") from None
    except DefusedXmlException as e:
        line = parser.parser.CurrentLineNumber
        if isinstance(e, DTDForbidden):
            what = f"<!DOCTYPE {e.name}>"
        else:
            what = f"<!ENTITY {e.name}>" if hasattr(e, "name") else "external reference"
        raise ModelError(
            f"{name}: {what} (line {line}): forbidden XML construct ({type(e).__name__}); "
            "DTDs and entities are not allowed"
        ) from None
    except ModelError as e:
        raise ModelError(f"{name}: {e}") from None
    except RecursionError:
        raise ModelError(f"{name}: XML nested too deeply") from None
    return root, parser.lines


def numbers(x) -> str:
    """Numbers as XML attribute text, exactly (``repr`` of each float, space separated)."""
    return " ".join(repr(float(v)) for v in np.atleast_1d(x))


def local_name(tag) -> str | None:
    """The tag without an XML namespace (``{uri}joint`` -> ``joint``); None for comments and
    processing instructions."""
    if not isinstance(tag, str):
        return None
    return tag.rsplit("}", 1)[-1] if tag.startswith("{") else tag
