"""Reading the documents users give the program (workcells, intrinsics, hand-eye files, workspaces,
solve inputs, board specs): one layer with limits, so no file can make a loader take unbounded time
or memory, and every refusal is a :class:`~calib_core.errors.FileFormatError` that names the file.

Limits are checked before the expensive step: the size before reading, the nesting depth and the
YAML aliases on the parser's event stream before building anything (a 6 KB alias "bomb" expands to
gigabytes once something walks it), JSON nesting on the text before parsing. They are far above
what any real cell needs (the bundled workcell is 5 KB, 4 levels deep, with no alias).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import yaml

from calib_core.errors import FileFormatError

if TYPE_CHECKING:
    import numpy as np

MAX_DOCUMENT_BYTES = 16 * 1024 * 1024
"""A workcell, an intrinsics or hand-eye file, a workspace of thousands of pairs: all far below."""
MAX_DEPTH = 64
MAX_ALIASES = 64

_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def read_text(path: str | Path, what: str, max_bytes: int = MAX_DOCUMENT_BYTES) -> str:
    """The UTF-8 text of ``path`` (a ``what``: "workcell file", ...), refused before reading when
    larger than ``max_bytes``."""
    path = Path(path)
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        raise FileFormatError(path, f"no such {what}") from None
    except OSError as exc:
        raise FileFormatError(path, f"cannot be read ({exc.strerror})") from None
    except ValueError as exc:  # a NUL byte in the name (a name read from another file)
        raise FileFormatError(str(path).replace("\0", "\\0"), f"is not a usable file name ({exc})") from None
    if path.is_dir():
        raise FileFormatError(path, f"is a folder, not a {what}")
    if not path.is_file():
        # A FIFO would block the read until a writer came (forever); a device would stream without end.
        raise FileFormatError(path, f"is not a regular file (a pipe or a device), not a {what}")
    if size > max_bytes:
        raise FileFormatError(path, f"is {_size(size)}; a {what} is at most {_size(max_bytes)}")
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)  # a file that grew (or a device) is still cut at the limit
    except OSError as exc:
        raise FileFormatError(path, f"cannot be read ({exc.strerror})") from None
    if len(data) > max_bytes:
        raise FileFormatError(path, f"is over {_size(max_bytes)}; a {what} is at most that")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FileFormatError(path, f"is not UTF-8 text (byte {exc.start})") from None


def parse_yaml(text: str, path: str | Path, *, max_depth: int = MAX_DEPTH, max_aliases: int = MAX_ALIASES):
    """The YAML document in ``text`` (safe types only), after checking its nesting and aliases on the
    event stream; ``FileFormatError`` naming ``path`` for bad YAML or a limit passed."""
    path = Path(path)
    depth = aliases = 0
    try:
        for event in yaml.parse(text, Loader=_Loader):
            if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                depth += 1
                if depth > max_depth:
                    raise FileFormatError(
                        path, f"nests deeper than {max_depth} levels (line {event.start_mark.line + 1})"
                    )
            elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                depth -= 1
            elif isinstance(event, yaml.AliasEvent):
                aliases += 1
                if aliases > max_aliases:
                    raise FileFormatError(
                        path,
                        f"uses more than {max_aliases} YAML aliases (*name); write the values out (line "
                        f"{event.start_mark.line + 1})",
                    )
        return yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as exc:
        if "flow level" in str(exc):  # libyaml's own nesting limit
            raise FileFormatError(path, f"nests deeper than {max_depth} levels") from None
        raise FileFormatError(path, f"not valid YAML ({_first_line(exc)})") from None
    except RecursionError:
        raise FileFormatError(path, f"nests deeper than {max_depth} levels") from None


def _json_depth_exceeds(text: str, max_depth: int) -> bool:
    depth, in_string, escaped = 0, False, False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            if depth > max_depth:
                return True
        elif ch in "]}":
            depth -= 1
    return False


def parse_json(text: str, path: str | Path, *, max_depth: int = MAX_DEPTH):
    """The JSON document in ``text``, its nesting checked first. ``NaN`` and ``Infinity`` (which
    Python writes for an unknown sigma) parse as floats: the fields that must be finite say so."""
    path = Path(path)
    if _json_depth_exceeds(text, max_depth):
        raise FileFormatError(path, f"nests deeper than {max_depth} levels")
    try:
        return json.loads(text)
    except (json.JSONDecodeError, ValueError) as exc:
        raise FileFormatError(path, f"not valid JSON ({exc})") from None
    except RecursionError:
        raise FileFormatError(path, f"nests deeper than {max_depth} levels") from None


def read_yaml(path: str | Path, what: str, **limits):
    """:func:`read_text` then :func:`parse_yaml`."""
    return parse_yaml(read_text(path, what, limits.pop("max_bytes", MAX_DOCUMENT_BYTES)), path, **limits)


def read_json(path: str | Path, what: str, **limits):
    """:func:`read_text` then :func:`parse_json`."""
    return parse_json(read_text(path, what, limits.pop("max_bytes", MAX_DOCUMENT_BYTES)), path, **limits)


def finite_number(
    value, path: str | Path, field: str, *, low: float = -math.inf, high: float = math.inf, exclusive_low: bool = False
) -> float:
    """``value`` as a finite float within [low, high] (``(low, high]`` with ``exclusive_low``), or a
    ``FileFormatError`` naming ``field``. Booleans are not numbers here."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise FileFormatError(path, f"must be a number, got {value!r}", field)
    v = float(value)
    if not math.isfinite(v):
        raise FileFormatError(path, f"must be a finite number, got {value!r}", field)
    if v < low or (exclusive_low and v == low) or v > high:
        bounds = (
            f"{'above' if exclusive_low else 'at least'} {low:g}"
            if high == math.inf
            else f"between {low:g} and {high:g}"
        )
        raise FileFormatError(path, f"must be {bounds}, got {value!r}", field)
    return v


def _size(n_bytes: int) -> str:
    return f"{n_bytes / 1e6:.1f} MB" if n_bytes >= 100_000 else f"{n_bytes / 1e3:.1f} kB"


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__


def csv_numbers(cells: list[str], columns: list[str], path: str | Path, where: str) -> list[float]:
    """The CSV ``cells`` of one row as finite floats, one per name in ``columns``; a
    ``FileFormatError`` naming the row (``where``) and the column of the first that is not."""
    values = []
    for column, cell in zip(columns, cells):
        try:
            number = float(cell.strip())
        except ValueError:
            raise FileFormatError(path, f"not a number: {cell.strip()!r}", f"{where}, {column}") from None
        values.append(finite_number(number, path, f"{where}, {column}"))
    return values


def read_grey_image(image_path: str | Path, listed_in: str | Path, where: str) -> "np.ndarray":
    """The image (h, w) uint8 grey that a row ``where`` of the file ``listed_in`` names. Refused with a
    :class:`FileFormatError`: a missing image names the list and its row, an unreadable one the image."""
    from calib_core.image_files import read_image

    image_path = Path(image_path)
    if not image_path.is_file():
        raise FileFormatError(listed_in, f"no such image {image_path}", where)
    return read_image(image_path, grey=True, where=where)
