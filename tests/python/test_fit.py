"""Fitting a part to a tubular mesh from Python: an elbow meshed here with
numpy (straight legs and a 90 degree bend, circles in the normal planes),
fitted and compared with the closed-form centre line and radius, and with
the fit.json of the command-line tool; a blob is refused naming the file."""

import math
import struct

import numpy as np
import pytest

import waam_slicer as ws
from conftest import read_json

LEG, BEND, RADIUS = 20.0, 40.0, 12.0


def centre(s):
    """Centre line of the elbow at arc length s (mm): up LEG, bend toward +x, along +x."""
    arc = BEND * math.pi / 2
    if s <= LEG:
        return np.array([0.0, 0.0, s])
    if s <= LEG + arc:
        a = (s - LEG) / BEND
        return np.array([BEND * (1 - math.cos(a)), 0.0, LEG + BEND * math.sin(a)])
    return np.array([BEND + s - LEG - arc, 0.0, LEG + BEND])


def normal_plane(s):
    """Unit tangent and the in-plane y axis (the bend stays in the xz plane)."""
    a = min(max(s - LEG, 0.0), BEND * math.pi / 2) / BEND
    t = np.array([math.sin(a), 0.0, math.cos(a)])
    return t, np.array([0.0, 1.0, 0.0])


def elbow_stl(path, h=1.0):
    length = 2 * LEG + BEND * math.pi / 2
    rings, around = int(math.ceil(length / h)), int(math.ceil(2 * math.pi * RADIUS / h))
    pts = []
    for i in range(rings + 1):
        s = length * i / rings
        t, y = normal_plane(s)
        x = np.cross(y, t)
        for j in range(around):
            v = 2 * math.pi * j / around
            pts.append(centre(s) + RADIUS * (math.cos(v) * x + math.sin(v) * y))
    tris = []
    for i in range(rings):
        for j in range(around):
            a, b = i * around + j, i * around + (j + 1) % around
            c, d = a + around, b + around
            tris += [(a, b, c), (b, d, c)]
    write_stl(path, np.array(pts), tris)
    return length


def write_stl(path, pts, tris):
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(tris)))
        for tri in tris:
            p = pts[list(tri)]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            n /= np.linalg.norm(n)
            f.write(struct.pack("<12fH", *n, *p[0], *p[1], *p[2], 0))


def test_an_elbow_is_fitted_within_the_goals(tmp_path, waam_cli):
    stl = tmp_path / "elbow.stl"
    length = elbow_stl(stl)
    part = ws.Part.from_mesh(stl, start="lowest")
    assert part.name == "elbow"
    report = part.fit_report
    assert report["skins"] == 1 and report["rms_mm"] < 0.02 and report["max_mm"] < 0.1
    assert abs(report["length_mm"] - length) < 0.5
    # Every station's centre within 0.05 mm of the closed-form centre line.
    line = np.array([centre(s) for s in np.linspace(0, length, 20001)])
    for st in report["stations"]:
        if st["centre_mm"] is not None:
            d = np.linalg.norm(line - np.array(st["centre_mm"]), axis=1).min()
            assert d < 0.05, st
            assert abs(st["law_radius_mm"] - RADIUS) < 0.05, st
    files = part.write_fit(tmp_path / "module")
    assert [f.name for f in files] == ["part.toml", "fit.json"]
    again = ws.Part.read(files[0])
    assert again.fit_report is None
    # The command-line tool writes the same report.
    code, err = waam_cli("fit", stl, "--out", tmp_path / "cli")
    assert code == 0, err
    cli = read_json(tmp_path / "cli" / "fit.json")
    assert cli["rms_mm"] == pytest.approx(report["rms_mm"], abs=1e-9)
    assert len(cli["stations"]) == len(report["stations"])
    assert (tmp_path / "cli" / "part.toml").read_text() == files[0].read_text()


def test_a_closed_blob_is_refused(tmp_path):
    # An octahedron: closed, no open end.
    pts = np.array([[10, 0, 0], [-10, 0, 0], [0, 10, 0], [0, -10, 0], [0, 0, 10], [0, 0, -10]], float)
    tris = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    stl = tmp_path / "blob.stl"
    write_stl(stl, pts, tris)
    with pytest.raises(ws.InputError, match=r"blob\.stl: not a tube"):
        ws.Part.from_mesh(stl)
    with pytest.raises(ws.InputError, match="start"):
        ws.Part.from_mesh(stl, start="sideways")


def collared_pipe_stl(path, r=10.0, length=80.0, outer=14.0, z0=36.0, z1=46.0, around=64):
    """A straight pipe of radius r about the z axis from z = 0 to length, rings
    1 mm apart, with a collar of radius outer from z0 to z1: flat rings at z0
    and z1 join the pipe to the collar (the generator of tests/fit/gen.rs)."""
    heights = [(r, z) for z in np.arange(0.0, z0 + 0.5)]
    heights += [(outer, z) for z in np.arange(z0, z1 + 0.5)]
    heights += [(r, z) for z in np.arange(z1, length + 0.5)]
    v = 2 * math.pi * np.arange(around) / around
    pts = np.array([[rad * math.cos(a), rad * math.sin(a), z] for rad, z in heights for a in v])
    tris = []
    for i in range(len(heights) - 1):
        for j in range(around):
            a, b = i * around + j, i * around + (j + 1) % around
            tris += [(a, b, a + around), (b, b + around, a + around)]
    write_stl(path, pts, tris)


def test_trim_fits_the_longest_tubular_stretch_and_names_the_collar(tmp_path):
    # A pipe of radius 10 from z = 0 to 80 with a collar of radius 14 from
    # z = 36 to 46: refused naming the collar; with trim=True the longest
    # tubular stretch (0 to 36; 46 to 80 is 2 mm shorter) is fitted and the
    # collar named in the report and in the fit.json written.
    stl = tmp_path / "collar.stl"
    collared_pipe_stl(stl)
    with pytest.raises(ws.InputError, match=r"collar\.stl: not a tube: a collar .*--trim"):
        ws.Part.from_mesh(stl)
    part = ws.Part.from_mesh(stl, trim=True)
    report = part.fit_report
    stations = report["stations"]
    h = 2 * (stations[1]["t_mm"] - stations[0]["t_mm"])
    # The fitted stretch: from the open end at z = 0 to the cut at z = 36,
    # the cut end named trimmed; the pipe's axis and radius.
    ends = sorted([report["start"], report["end"]], key=lambda e: e["centre_mm"][2])
    assert abs(ends[0]["centre_mm"][2]) <= 2 * h and abs(ends[1]["centre_mm"][2] - 36.0) <= 2 * h, ends
    assert [e["kind"] for e in ends] == ["open", "trimmed"], ends
    assert report["rms_mm"] < 0.05
    for st in stations:
        if st["centre_mm"] is not None:
            assert math.hypot(st["centre_mm"][0], st["centre_mm"][1]) < 0.05, st
            assert st["centre_mm"][2] < 36.0 + 2 * h, st
            assert abs(st["law_radius_mm"] - 10.0) < 0.05, st
    # The rest: the collar, 10 mm long, 4 mm high, 28 mm across.
    [collar] = report["features"]
    assert collar["kind"] == "collar", collar
    assert abs(collar["t_from_mm"] - 36.0) <= h and abs(collar["t_to_mm"] - 46.0) <= h, collar
    assert abs(collar["length_mm"] - 10.0) <= h, collar
    assert abs(collar["height_mm"] - 4.0) <= 0.2, collar
    assert abs(collar["across_mm"][1] - 28.0) <= 0.4, collar
    # All around the pipe (a lug, on one side, covers under 270 degrees).
    assert 270.0 <= collar["around_deg"] <= 360.0, collar
    files = part.write_fit(tmp_path / "module")
    written = read_json(files[1])
    assert written["features"] == report["features"]
    assert [written["start"]["kind"], written["end"]["kind"]] == [report["start"]["kind"], report["end"]["kind"]]
