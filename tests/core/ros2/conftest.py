import itertools
import os

import pytest

# ROS 2's safe domain ids are 0-101 on Linux: above, a domain's DDS ports fall in the ephemeral range (32768 and up),
# where any other socket (a GigE stream, a UDP client) may hold one ("failed to bind ... address in use"). Tests
# take 1-40, by process id, so two suites at once rarely share one.
_domains = itertools.count(os.getpid() % 40)


@pytest.fixture
def domain(monkeypatch):
    """A ROS domain of this test's own, so nothing else on the machine's DDS is heard."""
    value = 1 + next(_domains) % 40
    monkeypatch.setenv("ROS_DOMAIN_ID", str(value))
    return value
