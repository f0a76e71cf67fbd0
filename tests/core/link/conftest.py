"""The controller simulator as a real child process for the link tests: ``sim(*args)`` starts one (its link file in
the test's folder) and every one started is stopped after the test."""

import pytest

from tests.core.link.sim_process import SimProcess


@pytest.fixture
def sim(tmp_path):
    procs = []

    def start(*args, link=True):
        p = SimProcess(*args, link=tmp_path / "controller" if link else None)
        procs.append(p)
        return p

    yield start
    for p in procs:
        p.stop()
