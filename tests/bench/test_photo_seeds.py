"""The real-photo page's other draws of the priors: known answers on made-up rows."""

from __future__ import annotations

from dataclasses import replace

from bench.photo_runs import Row
from bench.photo_seeds import seeded_section


def _row(prior, mspd_px, seed, status="ok", width=640, colours=None, key="lmo_dev/test/000002/000001/0"):
    row = Row("lmo_dev", prior, key, status, 0.8, mspd_px, 1.0, 1.0, 1.0, 100.0, 0.5, width, colours_at=colours)
    return replace(row, seed=seed, obj_id=5, points_sigma_px=2.0)


def test_each_draw_counted_apart_and_each_wrong_ok_named_with_what_the_mesh_s_colours_say():
    rows = [
        _row((10.0, 3.0), 3.0, "a"),  # within 5 px, ok
        _row((10.0, 3.0), 11.5, "a", colours=(0.60, 0.40), key="lmo_dev/test/000002/000099/3"),  # wrong ok
        _row((10.0, 3.0), 40.0, "a", status="uncertain"),  # not an ok: not wrong
        _row((30.0, 10.0), 12.0, "b", colours=(0.30, 0.50)),  # wrong ok, the annotation's colours better
        _row((30.0, 10.0), float("inf"), "b", status="not found"),
    ]
    lines = seeded_section(rows)
    table = {tuple(c.strip() for c in x.strip("|").split("|")[1:3]): x for x in lines if x.startswith("| lmo_dev")}
    assert table[("10 mm / 3 deg", "a")] == "| lmo_dev | 10 mm / 3 deg | a | 3 | 1 | 2 | 1 | 1 | 0 |"
    assert table[("30 mm / 10 deg", "b")] == "| lmo_dev | 30 mm / 10 deg | b | 2 | 0 | 1 | 1 | 0 | 1 |"
    assert ("10 mm / 3 deg", "b") not in table  # nothing run: no row
    assert "Wrong `ok` over these draws: 2 of 3 answers called `ok`." in lines
    named = [x for x in lines if x.startswith("- ")]
    assert len(named) == 2 and named[0].startswith("- lmo_dev/test/000002/000099/3 (object 5, 80 % in sight)")
    assert "11.5 px off" in named[0] and "agree better at the answer (0.60 against 0.40)" in named[0]
    assert "agree better at the annotation (0.50 against 0.30)" in named[1]


def test_a_wrong_ok_on_a_wide_photo_is_counted_at_640_px():
    rows = [_row((30.0, 10.0), 36.0, "a", width=1920), _row((30.0, 10.0), 27.0, "a", width=1920)]  # 12 and 9 px
    lines = seeded_section(rows)
    assert "| lmo_dev | 30 mm / 10 deg | a | 2 | 0 | 2 | 1 | 0 | 0 |" in lines
    (named,) = [x for x in lines if x.startswith("- ")]
    assert "12.0 px off" in named and "stated 1-sigma 0.7 px" in named and "the mesh carries no colours" in named


def test_no_rows_nothing_said():
    assert seeded_section([]) == []
