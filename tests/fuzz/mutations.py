"""Hypothesis's mutations of a good document: a value anywhere replaced by another type, a huge, non-finite or
negative number, deep nesting or a long string; keys deleted or added; the text cut, aliased or nested past the
limits; a binary file's bytes changed (as a few numbers, applied in the test: Hypothesis keeps every value it
generates). :mod:`tests.fuzz.run_loader` runs them against each loader."""

from __future__ import annotations

import copy
from dataclasses import dataclass

from hypothesis import strategies as st


def _deep(depth: int):
    value: object = 1
    for _ in range(depth):
        value = [value]
    return value


nasty_values = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(
        [
            0,
            -1,
            1e308,
            -1e308,
            10**12,
            1e-320,
            "",
            "nan",
            ".inf",
            "1e12",
            "3",
            "../../etc/passwd",
            "<img src=x>",
            "\x00",
        ]
    ),
    st.text(max_size=30),
    st.lists(st.integers(-5, 5), max_size=6),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=3),
    st.integers(1, 120).map(_deep),
    st.integers(10_000, 200_000).map(lambda n: "x" * n),
)


def _paths(doc, prefix=()):
    """Every path to a value in a document of dicts and lists."""
    yield prefix
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _paths(v, prefix + (i,))


@st.composite
def mutated(draw, doc):
    """``doc`` with one to three mutations."""
    doc = copy.deepcopy(doc)
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        key = path[-1]
        op = draw(st.sampled_from(["replace", "replace", "replace", "delete", "add", "wrap"]))
        if op == "replace":
            parent[key] = draw(nasty_values)
        elif op == "delete":
            del parent[key]
        elif op == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=8))] = draw(nasty_values)
        elif op == "wrap":
            parent[key] = [parent[key]]
    return doc


@st.composite
def mutated_text(draw, text: str):
    """The text of a document cut, with bytes inserted, aliased or nested past the limits."""
    op = draw(st.sampled_from(["cut", "insert", "alias_bomb", "deep", "none"]))
    if op == "cut":
        return text[: draw(st.integers(0, len(text)))]
    if op == "insert":
        at = draw(st.integers(0, len(text)))
        return text[:at] + draw(st.text(max_size=20)) + text[at:]
    if op == "alias_bomb":
        levels = draw(st.integers(2, 12))
        bomb = "x0: &x0 [lol]\n" + "".join(
            f"x{i}: &x{i} [" + ", ".join([f"*x{i - 1}"] * 9) + "]\n" for i in range(1, levels)
        )
        return bomb + text
    if op == "deep":
        n = draw(st.integers(50, 20_000))
        return text + "\ndeep: " + "[" * n + "]" * n + "\n"
    return text


@dataclass(frozen=True)
class ByteMutation:
    """A binary file's mutation: ``cut`` at ``at``, ``flip`` the bytes ``values`` ((index, new byte), ...), or
    ``insert`` the bytes ``values`` at ``at``. Hypothesis keeps every value it generates until the run ends: kept as
    these few numbers, not as the mutated file (a 600 KB bag kept 10,000 times outgrew the fuzzed process's memory)."""

    op: str
    at: int = 0
    values: tuple | bytes = ()

    def of(self, data: bytes) -> bytes:
        if self.op == "cut":
            return data[: self.at]
        if self.op == "flip":
            out = bytearray(data)
            for index, value in self.values:
                out[index] = value
            return bytes(out)
        return data[: self.at] + bytes(self.values) + data[self.at :]


@st.composite
def byte_mutations(draw, size: int) -> ByteMutation:
    """A :class:`ByteMutation` of a file of ``size`` bytes: cut, with bytes overwritten, or with bytes inserted."""
    op = draw(st.sampled_from(["cut", "flip", "insert"]))
    if op == "cut":
        return ByteMutation("cut", draw(st.integers(0, size)))
    if op == "flip":
        count = draw(st.integers(1, 8))
        return ByteMutation(
            "flip", values=tuple((draw(st.integers(0, size - 1)), draw(st.integers(0, 255))) for _ in range(count))
        )
    return ByteMutation("insert", draw(st.integers(0, size)), draw(st.binary(max_size=64)))
