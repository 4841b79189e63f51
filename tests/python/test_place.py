"""Placing from Python: a hemisphere refused in a misplaced ROBOWAM
part-carried cell plans after `Part.place`, the placed cell is the one the
command-line tool writes, the joints of the plan in the placed cell stay
inside the cell file's joint limits, and bad keywords or bounds are named."""

import json
import tomllib

import numpy as np
import pytest

import waam_slicer as ws
from conftest import CELLS, PARTS

POINTS = 48  # per layer: small, to keep the search quick


def misplaced_text():
    """The ROBOWAM part-carried cell with its deposition point moved where
    the hemisphere is refused, and a box to search in (as the Rust test
    tests/optimise/place.rs)."""
    text = (CELLS / "robowam_part_carried.toml").read_text()
    moved = text.replace(
        "deposition_point_mm = [1045.747, -630.155, 653.167]",
        "deposition_point_mm = [700.0, -300.0, 400.0]",
    )
    assert moved != text
    return moved + "\n[placement]\nmin_mm = [600, -900, 300]\nmax_mm = [1300, 300, 1200]\n"


@pytest.fixture(scope="module")
def hemisphere():
    return ws.Part.read(PARTS / "hemisphere.toml")


@pytest.fixture(scope="module")
def placed(hemisphere):
    cell = ws.Cell.from_toml(misplaced_text(), name="misplaced.toml")
    assert not hemisphere.plan(cell, points=POINTS).feasible
    return hemisphere.place(cell, points=POINTS)


def body(toml_text):
    """A cell file without its comment lines (the header gives the time)."""
    return tomllib.loads(toml_text)


def test_a_refused_part_plans_in_the_placed_cell(hemisphere, placed):
    assert placed.feasible, placed.binding
    assert placed.binding is None
    plan = hemisphere.plan(placed.cell, points=POINTS)
    assert plan.feasible, plan.violations[:3]
    # The placed cell's file reads back as the same cell and plans the same.
    again = ws.Cell.from_toml(placed.toml, name="placed.toml")
    np.testing.assert_array_equal(hemisphere.plan(again, points=POINTS).joints, plan.joints)
    # Independent of the planner: every joint within the travel the cell
    # file gives (degrees, J6 unlimited in this cell).
    robot = tomllib.loads((CELLS / "robowam_part_carried.toml").read_text())["robot"]
    for j, (lo, hi) in enumerate(zip(robot["lower_deg"], robot["upper_deg"])):
        q = plan.joints[:, j]
        assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9), (j + 1, q.min(), q.max())
    # The values found are the placed file's deposition point, inside the
    # bounds searched.
    d = body(placed.toml)["part_carried"]["deposition_point_mm"]
    found = [placed.values[f"deposition_point_mm.{k}"] for k in "xyz"]
    np.testing.assert_allclose(found, d, atol=1e-6)
    for x, lo, hi in zip(found, [600, -900, 300], [1300, 300, 1200]):
        assert lo - 1e-9 <= x <= hi + 1e-9


def test_the_placed_cell_is_the_clis(placed, waam_cli, tmp_path):
    src = tmp_path / "misplaced.toml"
    src.write_text(misplaced_text())
    code, err = waam_cli(
        "place", PARTS / "hemisphere.toml", "--cell", src, "--points", POINTS,
        "--out", tmp_path / "cli",
    )
    assert code == 0, err
    cli = (tmp_path / "cli" / "cell.toml").read_text()
    assert body(cli) == body(placed.toml)
    written = placed.write(tmp_path / "py")
    assert [p.name for p in written] == ["placement.json", "cell.toml"]
    assert body(written[1].read_text()) == body(cli)
    ours = json.loads(written[0].read_text())
    theirs = json.loads((tmp_path / "cli" / "placement.json").read_text())
    for s in (ours, theirs):
        s.pop("times"), s.pop("time_s")
    assert ours == theirs
    summary = placed.summary()
    summary.pop("times"), summary.pop("time_s")
    assert summary == ours


def test_bad_keywords_and_bounds_are_named(hemisphere):
    cell = ws.Cell.read(CELLS / "robowam_part_carried.toml")
    with pytest.raises(ws.WaamError, match="samples = 0"):
        hemisphere.place(cell, samples=0)
    with pytest.raises(ws.WaamError, match="half_box_mm"):
        hemisphere.place(cell, half_box_mm=-1.0)
    bad = misplaced_text().replace("max_mm = [1300, 300, 1200]", "max_mm = [500, 300, 1200]")
    with pytest.raises(ws.WaamError, match="deposition_point_mm.x"):
        hemisphere.place(ws.Cell.from_toml(bad, name="bad.toml"), points=POINTS)
