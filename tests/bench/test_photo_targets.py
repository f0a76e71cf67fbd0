"""The real-photo page's targets: known answers on made-up rows."""

from __future__ import annotations

from bench.photo_targets import target_rows
from bench.photo_runs import FROM_TRUTH, ROBOTS_REACH, Row


def _row(dataset, prior, mspd_px, visible=1.0, status="ok", seconds=0.5, width=640, reach=None):
    return Row(dataset, prior, "k", status, visible, mspd_px, 1.0, 1.0, 1.0, 100.0, seconds, width, reach=reach)


def _cells(lines: list[str], target: str) -> list[str]:
    (line,) = [x for x in lines if x.startswith(f"| {target}")]
    return [c.strip() for c in line.strip("|").split("|")][1:]


def test_each_target_beside_what_each_set_measured_and_whether_it_is_met_everywhere():
    rows = [_row("lmo_dev", (10.0, 3.0), m) for m in (1.0, 2.0, 3.0, 4.0, 6.0)]  # 4 of 5 within 5 px: 80 %
    rows += [_row("lmo_dev", (10.0, 3.0), 2.0, visible=0.6)]  # 50-70 % in sight: 1 of 1
    rows += [_row("lmo_dev", (30.0, 10.0), 12.0, status="uncertain")]  # not counted as wrong: not `ok`
    rows += [_row("lmo_dev", FROM_TRUTH, 30.0, seconds=9.0)]  # the truth itself: no target counts it
    # HANDAL-like: 1920 px wide, 12 px there is 4 px at 640; a wrong `ok` of 40 px (13 at 640)
    rows += [_row("handal_dev", (10.0, 3.0), 12.0, width=1920, seconds=3.0)]
    rows += [_row("handal_dev", (30.0, 10.0), 40.0, width=1920, seconds=3.0)]
    lines = target_rows(rows)
    assert lines[0] == "| target | handal_dev | lmo_dev | met |"
    assert _cells(lines, "within MSPD 5 px from 10 mm / 3 deg, 70 %") == ["100 % (1 of 1)", "80 % (4 of 5)", "no"]
    assert _cells(lines, "within MSPD 5 px from 10 mm / 3 deg, 50-70 %") == ["-", "100 % (1 of 1)", "yes"]
    assert _cells(lines, "within MSPD 5 px from 30 mm / 10 deg") == ["0 % (0 of 1)", "0 % (0 of 1)", "no"]
    assert _cells(lines, "wrong `ok`") == ["1", "0", "no"]
    # the median over lmo_dev's 640 px views from the priors (0.5 s), the truth's 9 s left out; HANDAL has none
    assert _cells(lines, "a 640 x 480 view") == ["- (no 640 x 480 views)", "0.50 s", "yes"]
    assert not any("a bound" in line for line in lines)  # no run from the truth with a robot's reach: no bound said


def test_the_first_target_s_bound_is_said_from_the_truth_searched_as_far_as_a_robot_s_error():
    """The look started at the truth itself and searching 10 mm / 3 deg: its share within 5 px (70 % or more in sight)
    beside the target's, counted in no target (its 9 s and its 30 px answer neither)."""
    rows = [_row("lmo_dev", (10.0, 3.0), m) for m in (1.0, 2.0, 6.0, 7.0)]
    rows += [_row("lmo_dev", FROM_TRUTH, m, reach=ROBOTS_REACH, seconds=9.0) for m in (1.0, 2.0, 3.0, 30.0)]
    rows += [_row("lmo_dev", FROM_TRUTH, 1.0, reach=ROBOTS_REACH, visible=0.6)]  # under 70 % in sight: left out
    rows += [_row("lmo_dev", FROM_TRUTH, 30.0)]  # from the truth with the checks' reach: not the bound
    lines = target_rows(rows)
    assert _cells(lines, "within MSPD 5 px from 10 mm / 3 deg, 70 %") == ["50 % (2 of 4)", "no"]
    assert _cells(lines, "(a bound, not a target) within MSPD 5 px started at the truth itself, searching 10 mm") == [
        "75 % (3 of 4)",
        "-",
    ]
    assert not any("searching 30 mm" in line for line in lines)  # not run: not said
    assert _cells(lines, "wrong `ok`") == ["0", "yes"]
    assert _cells(lines, "a 640 x 480 view") == ["0.50 s", "yes"]


def test_no_rows_no_table():
    assert target_rows([]) == []


def test_wrong_ok_from_other_draws_of_the_priors_is_a_target_of_its_own():
    """Rows from other draws of the priors count in their own line only: the bench's own draw keeps its count."""
    rows = [_row("lmo_dev", (10.0, 3.0), 2.0)]
    seeded = [_seeded("lmo_dev", (10.0, 3.0), 11.0, "a"), _seeded("lmo_dev", (30.0, 10.0), 30.0, "b", "uncertain")]
    seeded += [_seeded("handal_dev", (30.0, 10.0), 36.0, "a", width=1920)]  # 12 px at 640: wrong
    lines = target_rows(rows + [_row("handal_dev", (10.0, 3.0), 3.0, width=1920)], seeded)
    assert _cells(lines, "wrong `ok` (over 10 px) from every prior") == ["0", "0", "yes"]
    assert _cells(lines, "wrong `ok` (over 10 px) from the other draws") == ["1", "1", "no"]
    assert not any("other draws" in line for line in target_rows(rows))  # none run: not said


def _seeded(dataset, prior, mspd_px, seed, status="ok", width=640):
    from dataclasses import replace

    return replace(_row(dataset, prior, mspd_px, status=status, width=width), seed=seed)
