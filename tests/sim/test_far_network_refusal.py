"""The far network needs root; without it the demo says so in one error line, and nothing is left half made."""

import pytest

from calib_core.errors import VideocalError
from videocal_sim import far_network
from videocal_sim.delay_line import LinkWeather


def test_without_root_the_far_network_is_refused_with_the_reason(monkeypatch):
    monkeypatch.setattr(far_network.os, "geteuid", lambda: 1000)
    assert "root" in far_network.why_not_available()
    with pytest.raises(
        VideocalError, match="cannot make a far network here: network namespaces and TAP devices need root"
    ):
        far_network.FarNetwork(LinkWeather(1.5, 0.3, 0.01))


def test_the_relay_command_refuses_too_and_says_why(monkeypatch, capsys):
    monkeypatch.setattr(far_network.os, "geteuid", lambda: 1000)
    assert far_network.main(["--one-way-ms", "1500"]) == 2
    assert capsys.readouterr().err.startswith("error: cannot make a far network here:")
