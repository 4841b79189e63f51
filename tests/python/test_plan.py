"""Planning from Python: joints against the command-line tool's joints.csv,
violations against the cell file's joint limits, an infeasible plan refusing
to write, a written program checked clean and a corrupted one not, progress
reports and the GIL released while planning."""

import csv
import json
import threading
import tomllib

import numpy as np
import pytest

import waam_slicer as ws
from conftest import CELLS, PARTS

POINTS = 40  # per layer: small, to keep the tests fast


@pytest.fixture(scope="module")
def hemisphere():
    return ws.Part.read(PARTS / "hemisphere.toml")


@pytest.fixture(scope="module")
def part_carried():
    return ws.Cell.read(CELLS / "robowam_part_carried.toml")


@pytest.fixture(scope="module")
def feasible(hemisphere, part_carried):
    plan = hemisphere.plan(part_carried, points=POINTS)
    assert plan.feasible, plan.violations[:3]
    return plan


def read_joints_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    return rows


@pytest.mark.parametrize(
    "cell_file,width",
    [("robowam_part_carried.toml", 6), ("robowam_torch_carried.toml", 8)],
)
def test_joints_are_the_clis(hemisphere, waam_cli, tmp_path, cell_file, width):
    cell = ws.Cell.read(CELLS / cell_file)
    plan = hemisphere.plan(cell, points=POINTS, rz="poly:2")
    code, err = waam_cli(
        "plan", PARTS / "hemisphere.toml", "--cell", CELLS / cell_file,
        "--points", POINTS, "--rz", "poly:2", "--out", tmp_path,
    )
    assert code == (0 if plan.feasible else 2), err
    rows = read_joints_csv(tmp_path / "joints.csv")
    names = ["j1", "j2", "j3", "j4", "j5", "j6"] + (["e1", "e2"] if width == 8 else [])
    want = np.array([[float(row[k]) for k in names] for row in rows])
    assert plan.joints.shape == want.shape == (len(plan), width)
    np.testing.assert_allclose(plan.joints, want, atol=2e-6)  # the file has 6 decimals
    xyz = np.array([[float(row[k]) for k in ("x", "y", "z")] for row in rows])
    np.testing.assert_allclose(plan.points, xyz, atol=2e-6)
    axes = np.array([[float(row[k]) for k in ("tx", "ty", "tz")] for row in rows])
    np.testing.assert_allclose(plan.tool_axis, axes, atol=2e-6)
    np.testing.assert_allclose(plan.rz_deg, [float(row["rz_deg"]) for row in rows], atol=2e-6)
    assert plan.layer.tolist() == [int(row["layer"]) for row in rows]
    for key, got in (
        ("travel_speed_mm_s", plan.point_speed_mm_s),
        ("wire_feed_mm_s", plan.wire_feed_mm_s),
    ):
        np.testing.assert_allclose(got, [float(row[key]) for row in rows], atol=2e-6)
    # nothing slowed on the hemisphere: the process's speed and wire feed
    # at every point (PLA, table 3.1: 6 mm/s, 10 mm/s)
    np.testing.assert_allclose(plan.point_speed_mm_s, plan.travel_speed_mm_s)
    np.testing.assert_allclose(plan.wire_feed_mm_s / plan.point_speed_mm_s, 10.0 / 6.0)


def test_infeasible_plan_refuses_to_write(hemisphere, part_carried, tmp_path):
    """R_Z held at 0 drives J5 past the cell's ±135° (thesis §3.3)."""
    plan = hemisphere.plan(part_carried, points=POINTS, rz="fixed:0")
    assert not plan.feasible
    assert "layer" in plan.refusal
    violations = plan.violations
    assert violations
    limits = tomllib.loads((CELLS / "robowam_part_carried.toml").read_text())["robot"]
    first_of_layer = {int(k): int(np.argmax(plan.layer == k)) for k in np.unique(plan.layer)}
    for v in violations:
        assert {"layer", "point", "joint", "what", "amount", "unit", "message"} <= v.keys()
        if v["what"] == "joint_limit":
            j = v["joint"]
            q = plan.joints[first_of_layer[v["layer"]] + v["point"], j - 1]
            lo, hi = limits["lower_deg"][j - 1], limits["upper_deg"][j - 1]
            assert q < lo or q > hi
            assert v["amount"] == pytest.approx(max(q - hi, lo - q), abs=1e-9)
            assert v["unit"] == "deg"
    assert any(v["what"] == "joint_limit" and v["joint"] == 5 for v in violations)
    out = tmp_path / "out"
    with pytest.raises(ws.InfeasiblePlan, match="hemisphere.toml"):
        plan.write_program(out)
    assert not out.exists(), "nothing written"
    assert issubclass(ws.InfeasiblePlan, ws.WaamError)


def test_a_folder_that_cannot_be_made_is_an_io_error(feasible, tmp_path):
    """Writing under a regular file fails in the OS, not in the input."""
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    with pytest.raises(ws.WaamIOError, match="a-file") as raised:
        feasible.write_program(blocker / "prog")
    assert isinstance(raised.value, OSError)


def test_check_program_round_trip(feasible, part_carried, tmp_path):
    files = feasible.write_program(tmp_path / "prog")
    assert files and files[0].name == "HEMISPHERE.ls"
    assert all(f.exists() for f in files)
    assert ws.check_program(files[0], part_carried) == []
    assert ws.check_program(str(files[0]), part_carried) == []
    # the cell's [program] table is in the files: home first, a 30 s dwell
    # between layers and payload updates (the check above verified them)
    main = files[0].read_text()
    assert "WAIT  30.00(sec)" in main or "WAIT 30.00(sec)" in main, main[:2000]
    assert "PAYLOAD[" in main
    # Move one joint target of the last program written out of J5's travel.
    target = files[-1]
    text = target.read_text()
    start = text.index("J5=", text.index("/POS"))
    end = text.index("deg", start)
    target.write_text(text[:start] + "J5=   170.0000 " + text[end:])
    problems = ws.check_program(files[0], part_carried)
    assert problems, "a J5 of 170° in a ±135° cell must be found"
    assert any(
        target.stem in p["file"] and "J5" in p["message"] and p["kind"] == "joint_limit"
        for p in problems
    ), problems
    assert all({"file", "line", "kind", "message"} <= p.keys() for p in problems)


def test_another_vendors_format_is_refused_before_planning(hemisphere, part_carried):
    # the format is asked once, when planning (Rust PlanOptions::format)
    with pytest.raises(ws.InputError, match="(?i)kuka|vendor|fanuc"):
        hemisphere.plan(part_carried, points=POINTS, format="kuka")
    with pytest.raises(ws.InputError, match="format"):
        hemisphere.plan(part_carried, points=POINTS, format="gcode")
    assert hemisphere.plan(part_carried, points=POINTS, format="fanuc").format == "fanuc"


def test_progress_reports_fractions_and_can_stop_the_plan(hemisphere, part_carried):
    seen = []
    plan = hemisphere.plan(part_carried, points=POINTS, rz="fixed:90", progress=seen.append)
    assert seen and seen == sorted(seen) and 0.0 <= seen[0] and seen[-1] == 1.0
    assert len(plan) > 0

    class Stop(Exception):
        pass

    def stop(fraction):
        raise Stop(fraction)

    with pytest.raises(Stop):
        hemisphere.plan(part_carried, points=POINTS, progress=stop)


def test_the_gil_is_released_while_planning(hemisphere, part_carried):
    """Another Python thread keeps running while a plan is computed."""
    done = []
    worker = threading.Thread(
        target=lambda: done.append(hemisphere.plan(part_carried, points=120))
    )
    ticks = 0
    worker.start()
    while worker.is_alive():
        ticks += 1
    worker.join()
    assert done and ticks > 10_000


def test_torch_carried_positioner_modes(waam_cli, tmp_path):
    """The positioner's laws (default) against the thesis's exact vertical:
    the elbow's first layers in the KUKA torch-carried cell; the summary is
    the CLI's, layer by layer (the largest tilt of b from the vertical within
    the cell's 15° cone); a bad mode names the keyword."""
    elbow = ws.Part.read(PARTS / "elbow.toml")
    cell = ws.Cell.read(CELLS / "kuka_kr16_2_torch_carried.toml")
    plans = {m: elbow.plan(cell, points=POINTS, max_layers=6, positioner=m)
             for m in ("optimised", "vertical")}
    for mode, plan in plans.items():
        assert plan.joints.shape[1] == 8
        code, err = waam_cli(
            "plan", PARTS / "elbow.toml", "--cell", CELLS / "kuka_kr16_2_torch_carried.toml",
            "--points", POINTS, "--max-layers", 6, "--positioner", mode,
            "--out", tmp_path / mode,
        )
        assert code == (0 if plan.feasible else 2), err
        rows = read_joints_csv(tmp_path / mode / "joints.csv")
        want = np.array([[float(r[k]) for k in ("e1", "e2")] for r in rows])
        np.testing.assert_allclose(plan.joints[:, 6:], want, atol=2e-6)
        with open(tmp_path / mode / "summary.json", encoding="utf-8") as f:
            layers = json.load(f)["layer_plans"]
        tilts = [layer["positioner"]["max_tilt_deg"] for layer in layers]
        assert all(t <= 15.0 + 1e-6 for t in tilts), tilts
    # the thesis's positioner keeps b vertical; the laws use the cone
    with open(tmp_path / "vertical" / "summary.json", encoding="utf-8") as f:
        assert all(layer["positioner"]["max_tilt_deg"] < 1e-6
                   for layer in json.load(f)["layer_plans"])
    with pytest.raises(ws.WaamError, match="positioner"):
        elbow.plan(cell, points=POINTS, max_layers=1, positioner="sideways")
