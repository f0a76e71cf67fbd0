"""Run every ``bench/*_bench.py``, ``bench/real_photos.py`` and ``bench/hand_eye_real.py`` (or the ones named on the
command line, each followed by its own options).

Each bench module has ``main() -> str``: it measures, writes its Markdown report to
``docs/benchmarks/<name>.md`` and returns the report's path. Timings never go in tests.
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    # names are the benches; what follows an option (``--views 60``) is the benches' own, read from sys.argv
    names = [a for k, a in enumerate(argv) if not a.startswith("-") and (k == 0 or not argv[k - 1].startswith("-"))]
    pages = sorted(p.stem for p in HERE.glob("*_bench.py")) + ["real_photos", "hand_eye_real"]
    names = names or pages
    unknown = [n for n in names if not (HERE / f"{n.removesuffix('.py')}.py").is_file()]
    if unknown:
        print(f"error: no bench named {', '.join(unknown)}; the benches: {', '.join(pages)}", file=sys.stderr)
        return 2
    failed = []
    for name in names:
        mod = importlib.import_module(f"bench.{name.removesuffix('.py')}")
        print(f"== {name}", flush=True)
        try:
            print(f"   wrote {mod.main()}", flush=True)
        except Exception as exc:  # one bench failing must not hide the others' figures
            print(f"   FAILED: {exc!r}", flush=True)
            failed.append(name)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
