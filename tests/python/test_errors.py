"""Bad input raises WaamError (a ValueError) with the library's message:
the file, the field, the keyword."""

import math

import pytest

import waam_slicer as ws
from conftest import CELLS, PARTS


@pytest.fixture(scope="module")
def torus():
    return ws.Part.read(PARTS / "quarter-torus.toml")


def test_errors_are_raised_by_kind():
    # one base, a subclass per kind (the library's ErrorKind); bad input is
    # still a ValueError, an unreadable file an OSError
    for kind in (ws.InputError, ws.InfeasiblePlan, ws.Cancelled, ws.WaamIOError):
        assert issubclass(kind, ws.WaamError)
    assert issubclass(ws.InputError, ValueError)
    assert issubclass(ws.WaamIOError, OSError)
    assert not issubclass(ws.WaamIOError, ValueError)
    assert not issubclass(ws.InfeasiblePlan, ValueError)


def test_a_missing_part_file_is_named(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ws.WaamIOError, match="nope.toml"):
        ws.Part.read(missing)


def test_a_bad_field_names_the_file_and_field():
    text = (PARTS / "quarter-torus.toml").read_text()
    bad = text.replace('radius = "r"', 'radius = "-r"')
    assert bad != text
    with pytest.raises(ws.InputError, match=r"my-torus\.toml: field `profile\.radius`"):
        ws.Part.from_toml(bad, name="my-torus.toml")
    with pytest.raises(ws.WaamError, match="my-torus.toml"):
        ws.Part.from_toml(text.replace("delta_mm = 5.0", 'delta_mm = "five"'), name="my-torus.toml")


def test_from_toml_reads_the_same_part_as_read():
    text = (PARTS / "quarter-torus.toml").read_text()
    a = ws.Part.from_toml(text, name="quarter-torus.toml").slice(points=40)
    b = ws.Part.read(PARTS / "quarter-torus.toml").slice(points=40)
    assert (a.points == b.points).all()


@pytest.mark.parametrize(
    "keywords,message",
    [
        (dict(delta_mm=-1.0), r"quarter-torus\.toml: slicing option `delta_mm`"),
        (dict(delta_mm=math.nan), r"quarter-torus\.toml: slicing option `delta_mm`"),
        (dict(points=1), r"quarter-torus\.toml: slicing option `points`"),
        (dict(points=-4), r"points = -4"),
        (dict(chord_mm=0.0), r"slicing option `chord_mm`"),
        (dict(points=50, chord_mm=0.1), r"points or chord_mm"),
        (dict(max_layers=0), r"`max_layers`"),
        (dict(strategy="spiralx"), r"strategy = \"spiralx\": expected one of constant"),
        (dict(travel_speed_mm_s=-3.0), r"quarter-torus\.toml: process parameter `travel_speed_mm_s`"),
    ],
)
def test_bad_keywords_name_the_keyword(torus, keywords, message):
    with pytest.raises(ws.InputError, match=message):
        torus.slice(**keywords)


def test_bad_plan_keywords(torus):
    cell = ws.Cell.read(CELLS / "robowam_part_carried.toml")
    with pytest.raises(ws.WaamError, match=r"rz = \"poly:9\""):
        torus.plan(cell, rz="poly:9")
    with pytest.raises(ws.WaamError, match="travel_speed_mm_s"):
        torus.plan(cell, points=40, travel_speed_mm_s=300.0)


def test_a_robot_file_is_not_a_cell():
    with pytest.raises(ws.InputError, match=r"kuka_kr16_2\.toml.*a robot, not a cell"):
        ws.Cell.read(CELLS / "kuka_kr16_2.toml")


def test_check_program_names_the_file(tmp_path):
    cell = ws.Cell.read(CELLS / "robowam_part_carried.toml")
    with pytest.raises(ws.WaamError, match="none.ls"):
        ws.check_program(tmp_path / "none.ls", cell)
    other = tmp_path / "prog.txt"
    other.write_text("")
    with pytest.raises(ws.WaamError, match=r"prog\.txt.*unknown program type"):
        ws.check_program(other, cell)
