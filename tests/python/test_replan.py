"""The closed loop from Python (issue 29): the elbow's layer 10 scanned
0.3 mm high everywhere (its straight leg: the build direction is +Z), the
remaining layers replanned in the ROBOWAM part-carried cell, and a scan of
the next layer refused naming the median error."""

import numpy as np
import pytest

import waam_slicer as ws
from conftest import CELLS, PARTS

GRID = dict(points=96, max_layers=14)


@pytest.fixture(scope="module")
def elbow():
    return ws.Part.read(PARTS / "elbow.toml")


@pytest.fixture(scope="module")
def cell():
    return ws.Cell.read(CELLS / "robowam_part_carried.toml")


def test_replan_from_points(elbow, cell, tmp_path):
    path = elbow.slice(**GRID)
    scan = path.points[path.layer == 10] + np.array([0.0, 0.0, 0.3])
    plan = elbow.replan(cell, scan, after_layer=10, **GRID)
    assert plan.feasible, plan.refusal
    assert plan.layer.min() == 11
    s = plan.summary()["replan"]
    assert abs(s["layers"][0]["error_before"]["mean_mm"] - 0.3) < 0.02
    assert s["layers"][0]["error_after"]["max_abs_mm"] < 0.3
    files = plan.write_program(tmp_path)
    assert files[0].name == "ELBOW_FROM_11.ls"
    assert ws.check_program(files[0], cell) == []


def test_scan_of_another_layer_is_refused(elbow, cell):
    path = elbow.slice(**GRID)
    scan = path.points[path.layer == 11]
    with pytest.raises(ws.InputError, match="median height error is \\+2.000 mm"):
        elbow.replan(cell, scan, after_layer=10, **GRID)
