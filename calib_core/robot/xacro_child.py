"""Expands one xacro file in a child process with bounded memory (``RLIMIT_AS``); the parent bounds its time.

Reads ``{"path", "roots", "args", "memory_mb"}`` as JSON on stdin; writes the URDF on stdout; on failure one line
on stderr and exit 2. ``$(find pkg)`` is answered from the roots (:mod:`calib_core.robot.ros_packages`), not from
``ament_index_python``, so no ROS is needed. Run by :func:`calib_core.robot.xacro_expand.expand_xacro` only.
"""

from __future__ import annotations

import json
import resource
import sys
from pathlib import Path


def main() -> int:
    request = json.loads(sys.stdin.read())
    limit = int(request["memory_mb"]) * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    if "cpu_s" in request:  # a runaway expression stops on its own even when nobody waits for it any more
        cpu = int(request["cpu_s"])
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))
    import xacro
    import xacro.substitution_args as substitution

    from calib_core.robot.ros_packages import find_package

    roots = [Path(p) for p in request["roots"]]
    missing: list[str] = []

    def find(name: str) -> str:
        found = find_package(name, roots)
        if found is None:
            looked = (
                ", ".join(str(r) for r in roots)
                or "nowhere (give --package-path, ROS_PACKAGE_PATH or AMENT_PREFIX_PATH)"
            )
            missing.append(f"$(find {name}): no package '{name}' (a package.xml naming it) in {looked}")
            raise substitution.SubstitutionException(missing[-1])
        return str(found)

    substitution._eval_find = find  # xacro asks ament_index_python, which needs a ROS install
    try:
        document = xacro.process_file(request["path"], mappings=dict(request["args"]))
        sys.stdout.write(document.toxml())
    except MemoryError:
        print(f"expanding it needed more than {request['memory_mb']} MB (a runaway expression?)", file=sys.stderr)
        return 2
    except BaseException as exc:  # xacro's own exceptions, NameError, IOError...: all mean "cannot expand"
        cause = exc
        while cause is not None:  # xacro wraps what went wrong in an expression
            if isinstance(cause, MemoryError) or isinstance(getattr(cause, "exc", None), MemoryError):
                print(
                    f"expanding it needed more than {request['memory_mb']} MB (a runaway expression?)", file=sys.stderr
                )
                return 2
            cause = cause.__cause__ or cause.__context__
        text = str(exc).strip().splitlines()
        print(missing[-1] if missing else (text[0] if text else type(exc).__name__), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
