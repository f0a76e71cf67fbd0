"""The tests' ROS 2 domains are reserved across processes: a domain one process holds is not given to another (two
test suites at once once shared one, and one suite's simulated arm answered the other's action client)."""

import json
import subprocess
import sys
from pathlib import Path

from tests.ros_domains import TEST_DOMAINS, reserved_domain

ROOT = Path(__file__).resolve().parent.parent
TAKE_EVERY_DOMAIN_IN_TURN = """
import json
from tests.ros_domains import TEST_DOMAINS, reserved_domain
seen = set()
for _ in TEST_DOMAINS:
    with reserved_domain() as domain:
        seen.add(domain)
print(json.dumps(sorted(seen)))
"""


def test_a_held_domain_is_given_to_no_one_else():
    with reserved_domain() as first:
        with reserved_domain() as second:
            assert second != first
        child = subprocess.run(
            [sys.executable, "-c", TAKE_EVERY_DOMAIN_IN_TURN], capture_output=True, text=True, timeout=60, cwd=ROOT
        )
        assert child.returncode == 0, child.stderr
        taken_by_the_child = set(json.loads(child.stdout))
        # (every other domain but those another test suite on the machine holds at the time)
        assert first not in taken_by_the_child and len(taken_by_the_child) >= len(TEST_DOMAINS) // 2
    with reserved_domain() as again:  # let go: free for the next test
        assert again in TEST_DOMAINS
