"""The set-up compiles every kernel signature a look uses (``make venv`` runs compile_kernels): the operator's first
look, Find points, Accept, Calibrate and Calibrate on edges, calls no kernel with a signature the set-up did not
(an array in another memory order is another signature: a first look once compiled seven kernels for 16 s)."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]

FIRST_LOOK = """
import json
from calib_core.solver.compile_kernels import called_signatures, compile_kernels
from tests.core.operator.still_robot import core_looking_at_task

compile_kernels()
set_up = called_signatures()
core, site, q, camera = core_looking_at_task()
found = core.finder.find_points()
core.finder.accept_found_points()
core.picking.calibrate()
verdict = core.session.result.verdict.verdict.value
core.finder.find_points()
edges = core.finder.calibrate_on_edges().solution.status.value
camera.close()
print(json.dumps({"found": len(found.result.proposals), "verdict": verdict, "edges": edges,
                  "new": sorted(map(list, called_signatures() - set_up))}))
"""


def test_a_first_look_after_the_set_up_calls_no_kernel_signature_the_set_up_did_not():
    # A process of its own: the suite's worker has run other solves before
    run = subprocess.run([sys.executable, "-c", FIRST_LOOK], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-3000:]
    look = json.loads(run.stdout.strip().splitlines()[-1])
    # the look was made (so its paths ran): points found, a calibration and a fit on edges
    assert look["found"] >= 4 and look["verdict"] == "ok" and look["edges"] == "ok", look
    assert look["new"] == [], "\n".join(" ".join(s)[:300] for s in look["new"])
