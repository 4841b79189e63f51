"""Slicing from Python: the quarter-torus distance figures of SPEC §3.2
computed from the numpy arrays alone, the arrays' layout, and the summary
against the command-line tool's summary.json."""

import math

import numpy as np
import pytest

import waam_slicer as ws
from conftest import PARTS, read_json

R, r, DELTA = 50.0, 15.0, 5.0


@pytest.fixture(scope="module")
def torus():
    return ws.Part.read(PARTS / "quarter-torus.toml")


def distance_to_layer_below(points, layer):
    """Each point's distance (mm) to the polyline of the layer below,
    recomputed here with numpy (NaN on the first layer). A layer's polyline
    is closed when its two ends are no further apart than its points."""
    out = np.full(len(points), np.nan)
    for k in range(1, layer.max() + 1):
        below = points[layer == k - 1]
        a, b = below[:-1], below[1:]
        gap = np.linalg.norm(below[0] - below[-1])
        if gap <= 1.5 * np.linalg.norm(b - a, axis=1).max():
            a, b = np.vstack([a, below[-1:]]), np.vstack([b, below[:1]])
        p = points[layer == k][:, None, :]
        ab = b - a
        s = np.clip(np.einsum("ijk,jk->ij", p - a, ab) / np.einsum("jk,jk->j", ab, ab), 0, 1)
        foot = a + s[..., None] * ab
        out[layer == k] = np.linalg.norm(p - foot, axis=2).min(axis=1)
    return out


def test_arrays_layout(torus):
    path = torus.slice(points=80)
    n = len(path)
    assert path.points.shape == (n, 3) and path.points.dtype == np.float64
    assert path.tool_axis.shape == (n, 3) and path.tool_axis.dtype == np.float64
    assert path.layer.shape == (n,) and path.layer.dtype == np.int64
    assert path.delta.shape == (n,) and path.delta.dtype == np.float64
    assert np.all(np.diff(path.layer) >= 0) and path.layer.max() == path.layers - 1
    np.testing.assert_allclose(np.linalg.norm(path.tool_axis, axis=1), 1.0, atol=1e-12)
    assert np.isnan(path.delta[path.layer == 0]).all()
    assert np.isfinite(path.delta[path.layer > 0]).all()
    assert not path.points.flags.writeable, "the arrays describe the path: read-only"
    with pytest.raises(ValueError):
        path.points[0, 0] = 1.0


def test_perpendicular_slicing_varies_by_60_percent(torus):
    """16 layers Delta apart along the guide: at profile angle v a point is
    rho = R + r cos v from the torus axis and 2 rho sin(Delta / 2R) from the
    layer below: ±30 % (SPEC §3.2, thesis fig. 2.6)."""
    path = torus.slice(strategy="perpendicular", delta_mm=DELTA, points=200)
    assert path.layers == 16
    d = path.delta[path.layer > 0]
    rel = d / DELTA - 1
    assert abs(rel.min() + 0.30) < 0.005 and abs(rel.max() - 0.30) < 0.005
    assert abs((rel.max() - rel.min()) - 0.60) < 0.005
    x, z = path.points[path.layer > 0, 0], path.points[path.layer > 0, 2]
    rho = np.hypot(x + R, z)
    np.testing.assert_allclose(d, 2 * rho * math.sin(DELTA / (2 * R)), atol=0.005 * DELTA)
    np.testing.assert_allclose(
        path.delta, distance_to_layer_below(path.points, path.layer), atol=1e-9
    )


def test_iso_path_drops_45_percent_only_downwards(torus):
    """The iso-v path with the same 16 layers: about -45 % on the inner
    side, never above Delta (SPEC §3.2: 45.1 %, thesis fig. 2.7)."""
    path = torus.slice(strategy="iso", delta_mm=DELTA, points=200, max_layers=16)
    assert path.layers == 16
    rel = path.delta / DELTA - 1
    assert np.nanmax(rel) <= 1e-9
    assert abs(np.nanmin(rel) + 0.451) < 0.01
    worst = np.nanargmin(rel)
    x, z = path.points[worst, 0], path.points[worst, 2]
    assert np.hypot(x + R, z) < R, "the minimum is on the inner side (v = pi)"
    np.testing.assert_allclose(
        path.delta, distance_to_layer_below(path.points, path.layer), atol=1e-9
    )


def test_constant_distance_is_constant(torus):
    """The constant-distance path: variation below 0.1 % (thesis ~0 %),
    checked on distances recomputed from the points."""
    path = torus.slice(strategy="constant", delta_mm=DELTA, points=200)
    d = distance_to_layer_below(path.points, path.layer)
    assert (np.nanmax(d) - np.nanmin(d)) / DELTA < 1e-3
    np.testing.assert_allclose(path.delta, d, atol=1e-9)
    assert path.points[:, 0].min() >= -R - 1e-9, "cut by the end plane X = -R"


def test_summary_is_the_clis_summary_json(torus, waam_cli, tmp_path):
    code, err = waam_cli(
        "slice", PARTS / "quarter-torus.toml", "--strategy", "perpendicular",
        "--points", 60, "--out", tmp_path,
    )
    assert code == 0, err
    cli = read_json(tmp_path / "summary.json")
    ours = torus.slice(strategy="perpendicular", points=60).summary()
    for s in (cli, ours):
        s.pop("run_time_s")
        s.pop("part_file")
    assert ours == cli
