import itertools
import os

import pytest

_domains = itertools.count(100 + os.getpid() % 50)


@pytest.fixture
def domain(monkeypatch):
    """A ROS domain of this test's own, so nothing else on the machine's DDS is heard."""
    value = next(_domains) % 233
    monkeypatch.setenv("ROS_DOMAIN_ID", str(value))
    return value
