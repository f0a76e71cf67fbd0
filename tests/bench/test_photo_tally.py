"""What the real-photo page counts over a list of rows: a known answer on made-up rows."""

from __future__ import annotations

from bench.photo_runs import Row, Tally


def _row(status: str, mspd_px: float, width: int = 640) -> Row:
    return Row("lmo_dev", (10.0, 3.0), "k", status, 0.8, mspd_px, 1.0, 1.0, 1.0, 100.0, 0.5, width)


def test_each_answer_counted_once_by_status_and_by_its_distance_at_640_px():
    rows = [
        _row("ok", 2.0),  # within 5 px
        _row("ok", 5.0),  # 5-10 px: 5 itself is not within
        _row("ok", 10.0),  # 10 px is still no wrong ok
        _row("ok", 10.5),  # wrong ok
        _row("ok", 27.0, width=1920),  # 9 px at 640 px width: not wrong
        _row("uncertain", 3.0),  # within 5 px though not an ok
        _row("not found", float("inf")),
    ]
    assert Tally.of(rows) == Tally(views=7, within_5=2, ok=5, ok_5_10=3, wrong_ok=1, uncertain=1, not_found=1)
