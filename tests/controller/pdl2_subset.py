"""A translator of the PDL2 subset the shipped controller program is written in, to Python, so the
tests can run the program's protocol logic (its parser, SHA-256, HMAC, session and moves) against the
workstation's real driver. Not a PDL2 implementation: it knows exactly the statements
``resources/controller/videocal_link.pdl`` uses, one per line, and fails loudly on anything else.

Semantics kept: 1-based arrays, ``DIV``/``MOD`` (the program applies them to non-negative operands
only, where PDL2's truncation and Python's floor agree), ``AND``/``OR``/``XOR`` bitwise on integers and
logical on booleans (every comparison they join is parenthesised in the program), ``ROUND`` half away
from zero, ``TRUNC`` toward zero, 32-bit ``INTEGER`` (the harness checks no value leaves that range).
Routines marked ``SITE`` are left out: the harness supplies them (serial port, clock, arm).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

_STRING = re.compile(r"'[^']*'")
_DECL = re.compile(r"^([a-z_][a-z0-9_]*(?:\s*,\s*[a-z_][a-z0-9_]*)*)\s*:\s*(.+)$")
_ARRAY = re.compile(r"^ARRAY\[(\d+)\] OF (INTEGER|REAL|BOOLEAN|STRING\[\d+\])$")
_ROUTINE = re.compile(r"^ROUTINE ([a-z_][a-z0-9_]*)(?:\((.*)\))?(?:\s*:\s*(INTEGER|REAL|BOOLEAN|STRING))?$")
_FOR = re.compile(r"^FOR ([a-z_][a-z0-9_]*) := (.+) (TO|DOWNTO) (.+) DO$")


class Pdl2SubsetError(ValueError):
    """A line outside the subset."""


@dataclass
class Routine:
    name: str
    params: list[str]
    site: bool
    locals: dict[str, str] = field(default_factory=dict)
    body: list[str] = field(default_factory=list)


def _initial(type_text: str) -> str:
    m = _ARRAY.match(type_text)
    if m:
        return f"[{_initial(m.group(2))}] * {int(m.group(1)) + 1}"
    if type_text == "INTEGER":
        return "0"
    if type_text == "REAL":
        return "0.0"
    if type_text == "BOOLEAN":
        return "False"
    if re.fullmatch(r"STRING\[\d+\]", type_text):
        return "''"
    raise Pdl2SubsetError(f"type {type_text!r}")


def _declarations(lines: list[str]) -> dict[str, str]:
    out = {}
    for line in lines:
        m = _DECL.match(line)
        if not m:
            raise Pdl2SubsetError(f"declaration {line!r}")
        for name in re.split(r"\s*,\s*", m.group(1)):
            out[name] = _initial(m.group(2))
    return out


def _params(text: str | None) -> list[str]:
    if not text:
        return []
    names = []
    for group in text.split(";"):
        left = group.split(":")[0]
        names += [n.strip() for n in left.split(",")]
    return names


def _strip_comment(line: str) -> str:
    quoted = False
    for k, ch in enumerate(line):
        if ch == "'":
            quoted = not quoted
        elif not quoted and line.startswith("--", k):
            return line[:k].rstrip()
    return line.rstrip()


def _lines(source: str) -> list[str]:
    return [_strip_comment(raw) for raw in source.splitlines()]


class Translator:
    def __init__(self, source: str):
        self.source = source
        self.consts: dict[str, str] = {}
        self.globals: dict[str, str] = {}
        self.routines: dict[str, Routine] = {}
        self.main: list[str] = []
        self._parse()

    def _parse(self) -> None:
        lines = _lines(self.source)
        raw = self.source.splitlines()
        i, section, site_next = 0, None, False
        while i < len(lines):
            line, text = lines[i].strip(), raw[i]
            i += 1
            if text.strip().startswith("--"):
                site_next = site_next or "SITE" in text
                continue
            if not line or line.startswith("PROGRAM "):
                continue
            if line in ("CONST", "VAR"):
                section = line
                continue
            if section == "CONST" and not line.startswith(("ROUTINE", "BEGIN")) and "=" in line:
                name, value = (s.strip() for s in line.split("=", 1))
                self.consts[name] = value
                continue
            if section == "VAR" and _DECL.match(line):
                self.globals.update(_declarations([line]))
                continue
            m = _ROUTINE.match(line)
            if m:
                routine = Routine(m.group(1), _params(m.group(2)), site_next)
                site_next, section = False, None
                local_lines = []
                if lines[i].strip() == "VAR":
                    i += 1
                    while lines[i].strip() != "BEGIN":
                        local_lines.append(lines[i].strip())
                        i += 1
                if lines[i].strip() != "BEGIN":
                    raise Pdl2SubsetError(f"line {i + 1}: BEGIN expected after ROUTINE {routine.name}")
                i += 1
                while lines[i].strip() != f"END {routine.name}":
                    routine.body.append(lines[i].strip())
                    i += 1
                i += 1
                routine.locals = _declarations(local_lines)
                self.routines[routine.name] = routine
                continue
            if line == "BEGIN":
                while not lines[i].strip().startswith("END "):
                    self.main.append(lines[i].strip())
                    i += 1
                return
            raise Pdl2SubsetError(f"line {i}: {line!r}")

    @property
    def site_routines(self) -> list[str]:
        return [r.name for r in self.routines.values() if r.site]

    def _expr(self, text: str) -> str:
        parts = re.split(r"('[^']*')", text)
        no_args = {r.name for r in self.routines.values() if not r.params}
        out = []
        for k, part in enumerate(parts):
            if k % 2:
                out.append(part)
                continue
            p = part.replace("<>", " != ").replace(":=", " := ")
            p = re.sub(r"(?<![<>!=:])=(?!=)", "==", p)
            for word, py in (
                ("AND", "&"),
                ("OR", "|"),
                ("XOR", "^"),
                ("NOT", "not"),
                ("DIV", "//"),
                ("MOD", "%"),
                ("TRUE", "True"),
                ("FALSE", "False"),
                ("STR_LEN", "len"),
                ("ORD", "_ord"),
                ("CHR", "_chr"),
                ("ABS", "abs"),
                ("TRUNC", "_trunc"),
                ("ROUND", "_round"),
            ):
                p = re.sub(rf"\b{word}\b", py, p)
            p = re.sub(
                r"\b([a-z_][a-z0-9_]*)\b(?!\s*\()",
                lambda m: m.group(1) + "()" if m.group(1) in no_args else m.group(1),
                p,
            )
            if re.search(r"\b[A-Z][A-Z_]+\b", p.replace("True", "").replace("False", "")):
                raise Pdl2SubsetError(f"unknown keyword in {text!r}")
            out.append(p)
        return "".join(out)

    def _statements(self, body: list[str], indent: int) -> list[str]:
        out, depth = [], indent
        for line in body:
            pad = "    " * depth
            if not line:
                continue
            if line.startswith("IF ") and line.endswith(" THEN"):
                out.append(f"{pad}if {self._expr(line[3:-5])}:")
                depth += 1
            elif line == "ELSE":
                out.append("    " * (depth - 1) + "else:")
            elif line in ("ENDIF", "ENDWHILE", "ENDFOR"):
                out.append(f"{pad}pass")
                depth -= 1
            elif line.startswith("WHILE ") and line.endswith(" DO"):
                out.append(f"{pad}while {self._expr(line[6:-3])}:")
                depth += 1
            elif m := _FOR.match(line):
                var, a, way, b = m.groups()
                rng = (
                    f"range({self._expr(a)}, ({self._expr(b)}) + 1)"
                    if way == "TO"
                    else f"range({self._expr(a)}, ({self._expr(b)}) - 1, -1)"
                )
                out.append(f"{pad}for {var} in {rng}:")
                depth += 1
            elif line == "RETURN":
                out.append(f"{pad}return None")
            elif line.startswith("RETURN(") and line.endswith(")"):
                out.append(f"{pad}return {self._expr(line[7:-1])}")
            elif " := " in line:
                target, value = line.split(" := ", 1)
                out.append(f"{pad}{self._expr(target)} = _int32({self._expr(value)})")
            elif re.fullmatch(r"[a-z_][a-z0-9_]*(\(.*\))?", line) and line.split("(")[0] in self.routines:
                out.append(f"{pad}{self._expr(line)}")
            else:
                raise Pdl2SubsetError(f"statement {line!r}")
        if depth != indent:
            raise Pdl2SubsetError("unbalanced blocks")
        return out

    def python(self) -> str:
        names = list(self.consts) + list(self.globals)
        src = [f"{k} = {v}" for k, v in self.consts.items()] + [f"{k} = {v}" for k, v in self.globals.items()]
        for r in self.routines.values():
            if r.site:
                continue
            src.append(f"def {r.name}({', '.join(r.params)}):")
            shared = [n for n in names if n not in r.params and n not in r.locals]
            if shared:
                src.append(f"    global {', '.join(shared)}")
            src += [f"    {k} = {v}" for k, v in r.locals.items()]
            src += self._statements(r.body, 1) or []
            src.append("    pass")
        src.append("def _main():")
        src.append(f"    global {', '.join(names)}")
        src += self._statements(self.main, 1)
        return "\n".join(src) + "\n"


def _int32(value):
    if isinstance(value, int) and not isinstance(value, bool) and not -(2**31) <= value < 2**31:
        raise OverflowError(f"INTEGER overflow: {value}")
    return value


def _round(x: float) -> int:
    return int(math.floor(abs(x) + 0.5)) * (1 if x >= 0 else -1)


def load(source: str, site: dict) -> dict:
    """The program as a namespace of Python functions (``_main`` is its body); ``site`` gives the
    SITE routines by name (every one must be there)."""
    t = Translator(source)
    missing = set(t.site_routines) - set(site)
    if missing:
        raise Pdl2SubsetError(f"the harness lacks the site routines {sorted(missing)}")
    namespace = {
        "_int32": _int32,
        "_round": _round,
        "_trunc": lambda x: int(x),
        "_ord": lambda s, i: ord(s[i - 1]),
        "_chr": chr,
        **site,
    }
    exec(compile(t.python(), "videocal_link.pdl (translated)", "exec"), namespace)
    return namespace
