# SPDX-License-Identifier: Apache-2.0
"""`import sweepers` from Debian's python3, checked against sweepers-cli and pyopenvdb.

Run by CTest (python.module) with PYTHONPATH at the build's python/ directory and
SWEEPERS_CLI and SWEEPERS_DATA set.
"""
import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pyopenvdb as vdb
import pytest

import sweepers

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import ply  # noqa: E402 (the tests' own PLY reader, in tests/)
from half_grid import rounding  # noqa: E402 (the tests' check of half-float files)

CLI = os.environ["SWEEPERS_CLI"]
DATA = os.environ["SWEEPERS_DATA"]
TWISTED = os.path.join(DATA, "twisted_limb.json")
RIGID = os.path.join(DATA, "studies", "rigid_motion.json")


# The CLI without what this interpreter needed to load a sanitized module (LD_PRELOAD of
# the sanitizers' runtime, which the CLI links itself).
CLI_ENV = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}


def cli(*args, check=True):
    return subprocess.run([CLI, *args], capture_output=True, text=True, check=check,
                          env=CLI_ENV)


def voxels(grid):
    """Every active voxel of a pyopenvdb grid: {(i, j, k): value}."""
    out = {}
    for it in grid.citerOnValues():
        if it.count == 1:
            out[it.min] = it.value
    return out


def read_ply(path):
    """The vertices (float32, n x 3) and triangles (int32) of a PLY the CLI wrote."""
    vertices, triangles = ply.read_ply(path)
    return np.array(vertices, dtype=np.float32), np.array(triangles, dtype=np.int32)


@pytest.fixture(scope="module")
def twisted(tmp_path_factory):
    d = tmp_path_factory.mktemp("twisted")
    out = cli("apply", TWISTED, "-o", str(d / "t.vdb"), "--mesh", str(d / "t.ply"), "--json")
    return sweepers.apply(TWISTED), json.loads(out.stdout), d


def test_version_is_the_programs():
    assert cli("--version").stdout.split()[-1] == sweepers.__version__


def test_examples_are_the_programs():
    # In the build tree, the checkout's data/, as `sweepers-cli examples` says.
    assert os.path.samefile(sweepers.examples(), DATA)
    assert sweepers.examples() == cli("examples").stdout.strip()


def test_apply_gives_what_the_cli_writes(twisted):
    shape, report, d = twisted
    assert shape.volume == pytest.approx(report["volume"], rel=1e-12)
    assert shape.topology == {"euler_characteristic": 2, "genus": 0, "components": 1}
    vertices, triangles = shape.mesh()
    assert vertices.dtype == np.float32 and vertices.shape[1] == 3
    assert triangles.dtype == np.int32 and triangles.shape[1] == 3
    ply_vertices, ply_triangles = read_ply(d / "t.ply")
    assert np.array_equal(vertices, ply_vertices)  # vertex for vertex
    assert np.array_equal(triangles, ply_triangles)
    grid = shape.to_pyopenvdb()
    written = vdb.read(str(d / "t.vdb"), "surface")
    assert grid.gridClass == written.gridClass and grid.background == written.background
    assert voxels(grid) == voxels(written)  # voxel for voxel
    assert len(voxels(grid)) == report["active_voxels"]


def test_save_writes_what_pyopenvdb_and_the_cli_read(twisted, tmp_path):
    shape, _, d = twisted
    shape.save(tmp_path / "s.vdb")
    shape.save(str(tmp_path / "s.ply"))
    assert voxels(vdb.read(str(tmp_path / "s.vdb"), "surface")) == voxels(
        vdb.read(str(d / "t.vdb"), "surface"))
    assert np.array_equal(read_ply(tmp_path / "s.ply")[0], read_ply(d / "t.ply")[0])
    info = json.loads(cli("info", str(tmp_path / "s.vdb"), "--json").stdout)
    assert info["volume"] == pytest.approx(shape.volume, rel=1e-12)


def test_save_at_half_precision_rounds_by_its_bound_and_reads_as_a_float_level_set(
        twisted, tmp_path):
    shape, _, d = twisted
    shape.save(tmp_path / "half.vdb", half=True)
    # Each value rounded by at most 1/2048 of itself, or of a voxel near the surface.
    rounding(str(d / "t.vdb"), str(tmp_path / "half.vdb"))
    assert os.path.getsize(tmp_path / "half.vdb") < 0.75 * os.path.getsize(d / "t.vdb")
    info = json.loads(cli("info", str(tmp_path / "half.vdb"), "--json").stdout)
    assert info["volume"] == pytest.approx(shape.volume, rel=1e-4)
    assert info["area"] == pytest.approx(shape.area, rel=1e-4)
    with pytest.raises(ValueError, match="only a .vdb is written at half precision"):
        shape.save(tmp_path / "half.ply", half=True)
    assert not (tmp_path / "half.ply").exists()


def test_without_numpy_the_error_names_the_debian_package():
    # An interpreter where numpy cannot be imported: sculpting works, and what needs an
    # array says what to install.
    code = """
import sys
sys.modules["numpy"] = None
import sweepers
s = sweepers.Sculptor(voxel_size=1 / 8)
s.apply({"type": "inflate", "at": [0, 1, 0], "radius": 0.4})
for call in (s.mesh, lambda: s.sample([[0.0, 0.0, 0.0]])):
    try:
        call()
    except ImportError as e:
        print(e)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=os.environ, check=True).stdout.splitlines()
    assert out == ["mesh: numpy is not installed (Debian: python3-numpy, for /usr/bin/python3)",
                   "sample: numpy is not installed (Debian: python3-numpy, for /usr/bin/python3)"
                   ], out


def test_a_script_as_a_dict_or_a_json_string_is_the_file(twisted):
    shape = twisted[0]
    text = open(RIGID).read()
    a = sweepers.apply(json.loads(text))
    b = sweepers.apply(text)
    c = sweepers.apply(RIGID, voxel_size=1 / 64)
    assert a.volume == b.volume == c.volume
    assert voxels(a.to_pyopenvdb()) == voxels(c.to_pyopenvdb())
    assert c.voxel_size == 1 / 64
    assert shape.voxel_size == json.load(open(TWISTED))["grid"]["voxel_size"]


STROKES = [
    {"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
                                 "path": [{"t": [0, 0.9, 0]}, {"t": [0, 1.3, 0.1]}]}]},
    {"type": "swirl", "at": [0, 0, 0.9], "move": [0, 0.2, 0.3], "radius": 0.35},
    {"type": "inflate", "at": [0.6, 0.6, 0], "radius": 0.3},
    {"type": "sweep", "mirror": "x",
     "tools": [{"shape": "ball", "size": 0.25, "falloff": 0.25,
                "path": [{"t": [0.5, -0.7, 0]}, {"t": [0.7, -0.9, 0]}]}]},
    {"type": "pinch", "at": [0, 0, 0], "axis": [0, 1, 0], "size": 1.25, "falloff": 0.4,
     "open": 0.3},
    {"type": "swirl", "at": [-0.9, 0, 0], "move": [-0.2, 0, 0], "radius": 0.3},
    {"type": "inflate", "at": [0, 0.4, -0.9], "radius": 0.25},
    {"type": "sweep", "tools": [{"shape": "ellipsoid", "size": [0.3, 0.2, 0.2],
                                 "falloff": 0.2,
                                 "path": [{"t": [0, 0, -1]}, {"t": [0.1, 0.2, -1.3]}]}]},
    {"type": "swirl", "at": [0.9, 0, 0], "move": [0.1, 0.1, 0], "radius": 0.3,
     "ring": "convolution"},
    {"type": "sweep", "tools": [{"shape": "ball", "size": 0.2, "falloff": 0.2,
                                 "path": [{"t": [-0.5, 0.7, 0.3]}, {"t": [-0.6, 0.9, 0.4]}]}]},
]


@pytest.fixture(scope="module")
def session():
    s = sweepers.Sculptor(voxel_size=1 / 32)
    for stroke in STROKES:
        s.apply(stroke)
    return s


def test_a_sessions_script_replays_to_the_same_grid(session, tmp_path):
    script = session.script()
    assert [s["type"] for s in script["strokes"]] == [s["type"] for s in STROKES]
    (tmp_path / "session.json").write_text(json.dumps(script))
    cli("apply", str(tmp_path / "session.json"), "-o", str(tmp_path / "replay.vdb"))
    replay = voxels(vdb.read(str(tmp_path / "replay.vdb"), "surface"))
    assert voxels(session.to_pyopenvdb()) == replay


def test_undo_then_redo_gives_the_same_grid(session):
    before = voxels(session.to_pyopenvdb())
    volume = session.volume
    assert session.undo() and session.undo()
    assert len(session.script()["strokes"]) == len(STROKES) - 2
    assert session.volume != volume
    assert session.redo() and session.redo() and not session.redo()
    assert voxels(session.to_pyopenvdb()) == before
    assert len(session.script()["strokes"]) == len(STROKES)


def test_a_list_of_strokes_is_one_undo_step():
    s = sweepers.Sculptor(voxel_size=1 / 16)
    start = s.volume
    s.apply(STROKES[:3])
    assert s.volume != start
    assert s.undo() and not s.can_undo
    assert s.volume == start


def test_a_sculptor_starts_from_a_vdb_or_a_mesh(twisted):
    shape, _, d = twisted
    from_vdb = sweepers.Sculptor(d / "t.vdb")
    assert from_vdb.voxel_size == shape.voxel_size
    assert voxels(from_vdb.to_pyopenvdb()) == voxels(shape.to_pyopenvdb())
    from_mesh = sweepers.Sculptor(str(d / "t.ply"), voxel_size=shape.voxel_size)
    assert from_mesh.volume == pytest.approx(shape.volume, rel=0.01)
    assert from_mesh.script()["start"]["mesh"] == str(d / "t.ply")


def grab(strength=None, stroke="sweep"):
    """A unit sphere at 1/32 with the top grabbed 0.4 up (or a swirl, an inflation or a fluid
    push there)."""
    strokes = {
        "sweep": {"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
                                             "path": [{"t": [0, 1, 0]}, {"t": [0, 1.4, 0]}]}]},
        "swirl": {"type": "swirl", "at": [0, 0.9, 0], "move": [0, 0.4, 0], "radius": 0.3},
        "inflate": {"type": "inflate", "at": [0, 0.9, 0], "radius": 0.3},
        "fluid": {"type": "fluid", "radius": 0.3, "path": [[0, 0.85, 0], [0, 1.25, 0]]},
    }
    stroke = dict(strokes[stroke])
    if strength is not None:
        stroke["strength"] = strength
    return sweepers.apply({"sweepers": 1, "grid": {"voxel_size": 1 / 32},
                           "start": {"sphere": {"center": [0, 0, 0], "radius": 1}},
                           "strokes": [stroke]})


def top(shape):
    """The highest point of the surface on the y axis (where the grid crosses zero)."""
    ys = np.linspace(0.5, 2.0, 3001)
    d = shape.sample(np.stack([np.zeros_like(ys), ys, np.zeros_like(ys)], axis=1))
    k = np.nonzero(d > 0)[0][0]  # the first sample outside, going up
    return ys[k - 1] + (ys[k] - ys[k - 1]) * (-d[k - 1]) / (d[k] - d[k - 1])


def test_a_grab_of_strength_half_moves_the_surface_half_as_far():
    start = sweepers.Sculptor(voxel_size=1 / 32)
    full, half = grab(), grab(0.5)
    moved_full, moved_half = top(full) - top(start), top(half) - top(start)
    print(f"the top moved {moved_full:.4f} at strength 1, {moved_half:.4f} at 0.5")
    assert moved_full > 0.3
    assert abs(moved_half - moved_full / 2) < 1 / 32  # within a voxel
    # Strength 1 is the stroke as it was, voxel for voxel.
    assert voxels(grab(1.0).to_pyopenvdb()) == voxels(full.to_pyopenvdb())
    # A swirl's move, an inflation's radius and a fluid push take it too.
    for kind in ("swirl", "inflate", "fluid"):
        assert top(grab(0.5, kind)) - top(start) < 0.8 * (top(grab(None, kind)) - top(start))


def test_a_strength_is_kept_in_the_script_and_refused_outside_its_range():
    s = sweepers.Sculptor(voxel_size=1 / 16)
    s.apply({"type": "swirl", "at": [0, 0.9, 0], "move": [0, 0.3, 0], "radius": 0.3,
             "strength": 0.25})
    assert s.script()["strokes"][0]["strength"] == 0.25
    with pytest.raises(ValueError, match="strength"):
        s.apply({"type": "inflate", "at": [0, 1, 0], "radius": 0.2, "strength": 1.5})
    with pytest.raises(ValueError, match="strength"):
        s.apply({"type": "pinch", "at": [0, 0, 0], "axis": [0, 1, 0], "size": 1.25,
                 "falloff": 0.4, "open": 0.3, "strength": 0.5})


RADIAL_STROKES = {
    "sweep": {"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
                                          "path": [{"t": [0.6, 0.8, 0]},
                                                   {"t": [0.8, 1.1, 0.1]}]}]},
    "inflate": {"type": "inflate", "at": [0.6, 0.7, 0.1], "radius": 0.2},
    "swirl": {"type": "swirl", "at": [0.6, 0.8, 0], "move": [0.15, 0.2, 0.05], "radius": 0.2},
    "smooth": {"type": "smooth", "tool": {"shape": "ball", "size": 0.3, "falloff": 0.1,
                                          "path": [{"t": [0.6, 0.8, 0]}]}},
}


def radial_grab(count=None, kind="sweep"):
    """A unit sphere at 1/32 with a stroke off the y axis (a bump pulled out, a ball of clay,
    a swirl, a smooth dab, and then the stroke before it), radially repeated."""
    stroke = dict(RADIAL_STROKES[kind])
    if count:
        stroke["radial"] = {"axis": [0, 1, 0], "center": [0, 0, 0], "count": count}
    strokes = [stroke]
    if kind == "smooth":  # something to smooth: the bump, five times (count 0: only that)
        strokes = [dict(RADIAL_STROKES["sweep"], radial={"axis": [0, 1, 0], "center": [0, 0, 0],
                                                        "count": 5})] + strokes[count == 0:]
    return sweepers.apply({"sweepers": 1, "grid": {"voxel_size": 1 / 32},
                           "start": {"sphere": {"center": [0, 0, 0], "radius": 1}},
                           "strokes": strokes})


def turned_rms(shape, count):
    """The RMS difference (voxels) between the grid at the voxels next to its surface and at
    the same points turned by 360 / count degrees about y, sampled trilinearly."""
    h = shape.voxel_size
    grid = shape.to_pyopenvdb()
    near = [c for c, v in voxels(grid).items() if abs(v) < h]
    points = np.array([grid.transform.indexToWorld(c) for c in near])
    turn = 2 * np.pi / count  # about y: (x, z) turned
    turned = points.copy()
    turned[:, 0] = np.cos(turn) * points[:, 0] + np.sin(turn) * points[:, 2]
    turned[:, 2] = -np.sin(turn) * points[:, 0] + np.cos(turn) * points[:, 2]
    return np.sqrt(np.mean((shape.sample(points) - shape.sample(turned)) ** 2)) / h


def test_radial_symmetry_makes_the_grid_symmetric():
    shape = radial_grab(5)
    rms = turned_rms(shape, 5)
    alone = radial_grab()
    print(f"5-fold: RMS difference {rms:.4f} voxel; "
          f"volume {shape.volume:.4f} against {alone.volume:.4f} for one bump")
    assert rms < 0.05
    # Five bumps: the volume grows about five times as much as for one.
    start = 4 / 3 * np.pi
    assert 4.0 < (shape.volume - start) / (alone.volume - start) < 6.0
    # A count of 1 is the stroke alone, voxel for voxel.
    assert voxels(radial_grab(1).to_pyopenvdb()) == voxels(alone.to_pyopenvdb())
    with pytest.raises(ValueError, match="count"):
        radial_grab(65)


@pytest.mark.parametrize("kind", ["inflate", "swirl", "smooth"])
def test_radial_symmetry_on_clay_swirls_and_smoothing(kind):
    # Their copies are applied one after another (they are no tools to sweep together):
    # still 5-fold symmetric, and a count of 1 is the stroke alone.
    shape, alone = radial_grab(5, kind), radial_grab(None, kind)
    rms = turned_rms(shape, 5)
    print(f"{kind}, 5-fold: RMS difference {rms:.4f} voxel (alone: {turned_rms(alone, 5):.4f})")
    assert rms < 0.05
    assert voxels(radial_grab(1, kind).to_pyopenvdb()) == voxels(alone.to_pyopenvdb())
    if kind == "swirl":  # keeps the volume: one swirl alone is far from symmetric
        assert turned_rms(alone, 5) > 4 * rms
    elif kind == "inflate":  # five balls of clay: about five times the volume of one
        start = 4 / 3 * np.pi
        assert 4.0 < (shape.volume - start) / (alone.volume - start) < 6.0
    else:  # each of the five dabs smooths its copy of the bump alike
        bumps = radial_grab(0, "smooth")
        rng = np.random.default_rng(3)
        around = rng.uniform(-0.3, 0.3, size=(20000, 3))
        changes = []
        for k in range(5):
            a = 2 * np.pi * k / 5
            c = np.array([0.6 * np.cos(a), 0.8, -0.6 * np.sin(a)])
            p = c + around
            p = p[np.abs(bumps.sample(p)) < shape.voxel_size]  # next to the surface
            d = shape.sample(p) - bumps.sample(p)
            changes.append(np.sqrt(np.mean(d ** 2)) / shape.voxel_size)
        print("  each copy's change, voxels RMS:", " ".join(f"{c:.3f}" for c in changes))
        # (A dab moves a bump this well resolved by hundredths of a voxel; each copy of it
        # moves, by about as much.)
        assert min(changes) > 0.002 and max(changes) < 1.5 * min(changes)


def test_smoothing_has_no_exact_shape_behind_it():
    # A smooth dab relaxes the surface (a sphere shrinks a little, by mean-curvature flow),
    # is recorded, undone like any stroke, and leaves no exact reference to measure against.
    sculptor = sweepers.Sculptor(voxel_size=1 / 32)
    before = sculptor.volume
    sculptor.apply({"type": "smooth", "strength": 1.0,
                    "tool": {"shape": "ball", "size": 0.4, "falloff": 0.2,
                             "path": [{"t": [0, 1, 0]}, {"t": [0.1, 0.99, 0]}]}})
    assert 0.99 * before < sculptor.volume < before
    assert sculptor.script()["strokes"][0]["type"] == "smooth"
    with pytest.raises(ValueError, match="no exact shape"):
        sculptor.shape().exact_distance(np.zeros((1, 3)))
    sculptor.undo()
    assert sculptor.volume == before


def test_exact_distance_is_the_moved_sphere():
    # rigid_motion.json carries a sphere of radius 0.5 rigidly, inside a tool that holds it
    # whole: its exact shape is the sphere at the path's last placement.
    shape = sweepers.apply(RIGID, voxel_size=1 / 32)
    rng = np.random.default_rng(7)
    directions = rng.normal(size=(1000, 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    center = np.array([0.45, 0.2, -0.1])
    radii = rng.uniform(0.45, 0.55, size=1000)
    points = center + directions * radii[:, None]
    exact = shape.exact_distance(points)
    assert exact.shape == (1000,)
    assert np.max(np.abs(exact - (radii - 0.5))) < 1e-9
    # The grid is within a fraction of a voxel of it.
    assert np.sqrt(np.mean((shape.sample(points) - exact) ** 2)) < 0.1 / 32


def test_exact_distance_is_a_distance_near_the_surface_and_the_starts_far_away():
    # A unit sphere whose top a ball tool (size 0.5, falloff 0.5) pulls up by 0.3: inside the
    # ball the map is a translation, in its falloff it stretches space, beyond it is the
    # identity.
    s = sweepers.Sculptor(voxel_size=1 / 16)
    s.apply({"type": "sweep", "tools": [{"shape": "ball", "size": 0.5, "falloff": 0.5,
             "path": [{"t": [0, 1, 0]}, {"t": [0, 1.3, 0]}]}]})
    shape = s.shape()
    value = lambda x: shape.exact_value(np.array([x]))[0]
    distance = lambda x: shape.exact_distance(np.array([x]))[0]

    def on_surface(angle):  # where exact_value changes sign, along a ray in the xy plane
        d = np.array([np.sin(np.radians(angle)), np.cos(np.radians(angle)), 0.0])
        lo, hi = 0.2, 3.0
        for _ in range(60):
            lo, hi = ((lo + hi) / 2, hi) if value(d * (lo + hi) / 2) < 0 else (lo, (lo + hi) / 2)
        p = d * lo
        g = np.array([value(p + 1e-6 * e) - value(p - 1e-6 * e) for e in np.eye(3)])
        return p, g / np.linalg.norm(g)

    # Within the ball the history is rigid: a point delta off the surface along its normal
    # is at distance delta, and both functions say so.
    p, n = on_surface(20)
    for delta in (0.04, -0.02):
        assert abs(distance(p + delta * n) - delta) < 1e-8
        assert abs(value(p + delta * n) - delta) < 1e-8
    # In the falloff the value is stretched (off by about a third of delta); the distance
    # is off by the square of delta: halving delta divides its error by four or more.
    for angle in (30, 40):
        p, n = on_surface(angle)
        errors = []
        for delta in (0.02, 0.01):
            x = p + delta * n
            errors.append(abs(distance(x) - delta))
            assert abs(value(x) - delta) > 0.2 * delta, (angle, delta, value(x))
            assert abs(distance(x) - delta) < 0.05 * delta, (angle, delta, distance(x))
        assert errors[0] / errors[1] > 3, (angle, errors)
    # Far from the surface neither is the shape's distance: above the pulled top (at 1.3),
    # where no tool reached, both are the distance to the start's surface.
    vertices, _ = shape.mesh()
    assert abs(vertices[:, 1].max() - 1.3) < 0.01
    assert abs(distance([0, 2.6, 0]) - 1.6) < 1e-9 and abs(value([0, 2.6, 0]) - 1.6) < 1e-12


def test_sample_is_the_grid_pyopenvdb_reads(twisted):
    shape = twisted[0]
    grid = shape.to_pyopenvdb()
    acc = grid.getConstAccessor()
    rng = np.random.default_rng(3)
    lo, hi = np.array(grid.evalActiveVoxelBoundingBox())
    h = shape.voxel_size
    points = rng.uniform(lo * h - 0.1, hi * h + 0.1, size=(1000, 3))
    sampled = shape.sample(points)
    # Trilinear interpolation of the voxels, here by hand.
    expected = []
    for p in points:
        x = np.array(grid.transform.worldToIndex(tuple(p)))
        base = np.floor(x).astype(int)
        f = x - base
        value = 0.0
        for corner in range(8):
            o = np.array([(corner >> 2) & 1, (corner >> 1) & 1, corner & 1])
            w = np.prod(np.where(o == 1, f, 1 - f))
            value += w * acc.getValue(tuple(int(c) for c in base + o))
        expected.append(value)
    assert np.max(np.abs(sampled - np.array(expected))) < 1e-6


def test_to_vdb_bytes_is_what_pyopenvdb_unpickles(twisted):
    shape = twisted[0]
    data = shape.to_vdb_bytes()
    assert isinstance(data, bytes) and len(data) > 1000
    grid = vdb.FloatGrid()
    grid.__setstate__(({}, data))
    assert voxels(grid) == voxels(shape.to_pyopenvdb())


def test_a_study_gives_the_clis_table(tmp_path):
    rows = sweepers.study([RIGID, TWISTED], ["1/16", 1 / 32], ["trilinear", "cubic"],
                          directory=tmp_path / "py")
    import pandas
    assert isinstance(rows, pandas.DataFrame) and len(rows) == 8
    cli("study", RIGID, TWISTED, "-o", str(tmp_path / "cli"), "--voxel-sizes", "1/16,1/32",
        "--variants", "trilinear,cubic", "-q")
    table = list(csv.DictReader(open(tmp_path / "cli" / "study.csv")))
    for row, (_, frame) in zip(table, rows.iterrows()):
        assert (row["script"], row["variant"]) == (frame["script"], frame["variant"])
        assert float(row["err_rms"]) == pytest.approx(frame["err_rms"], rel=1e-6)
        assert int(row["active_voxels"]) == frame["active_voxels"]
    # Without a directory: a temporary one, removed.
    again = sweepers.study(RIGID, [1 / 16], "trilinear")
    assert list(again["err_rms"]) == [rows["err_rms"][0]]
    # What its runs keep changes no row.
    kept = sweepers.study(RIGID, [1 / 16], "trilinear", directory=tmp_path / "kept",
                          keep="grids", half=True)
    assert list(kept["err_rms"]) == [rows["err_rms"][0]]
    run = tmp_path / "kept" / "runs" / "rigid_motion-trilinear_16"
    assert not (run / "mesh.ply").exists()
    assert vdb.read(str(run / "grid.vdb"), "surface").metadata["is_saved_as_half_float"]
    with pytest.raises(ValueError, match="keep: 'some' is not one of both, grids, meshes, none"):
        sweepers.study(RIGID, [1 / 16], "trilinear", keep="some")


def test_bad_input_raises_with_the_clis_message(tmp_path):
    bad = {"sweepers": 1, "strokes": [{"type": "smudge"}]}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    said = cli("apply", str(tmp_path / "bad.json"), "-o", str(tmp_path / "x.vdb"),
               check=False).stderr.strip()
    with pytest.raises(ValueError) as e:
        sweepers.apply(str(tmp_path / "bad.json"))
    assert "sweepers-cli: " + str(e.value) == said
    with pytest.raises(ValueError, match="unknown stroke type"):
        sweepers.apply(bad)
    with pytest.raises(ValueError, match="voxel_size must be a positive number"):
        sweepers.apply(RIGID, voxel_size=float("nan"))
    missing = str(tmp_path / "missing.json")
    said = cli("apply", missing, "-o", str(tmp_path / "x.vdb"), check=False).stderr.strip()
    with pytest.raises(OSError) as e:
        sweepers.apply(missing)
    assert "sweepers-cli: " + str(e.value) == said
    with pytest.raises(ValueError):
        sweepers.apply({"sweepers": 1, "strokes": {"type": "sweep"}})  # not a list
    with pytest.raises(ValueError):
        sweepers.Sculptor().apply({"type": "sweep", "tools": "ball"})
    with pytest.raises(ValueError, match="n x 3"):
        sweepers.apply(RIGID).sample(np.zeros((4, 2)))
    with pytest.raises(TypeError):
        sweepers.apply(42)


def test_progress_reaches_the_end_and_its_errors_stop_the_work():
    seen = []
    sweepers.apply(TWISTED, voxel_size=1 / 32, progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1][0] == seen[-1][1] and [d for d, _ in seen] == list(
        range(1, len(seen) + 1))

    def fail(done, total):
        raise RuntimeError("stop here")

    s = sweepers.Sculptor(voxel_size=1 / 32)
    with pytest.raises(RuntimeError, match="stop here"):
        s.apply(STROKES[:2], progress=fail)
    assert s.script()["strokes"] == [] and not s.can_undo


PINCH = {"type": "pinch", "at": [0, 0, 0], "axis": [0, 1, 0], "size": 1.25, "falloff": 0.4,
         "open": 0.3}


def test_ctrl_c_cancels_and_leaves_the_sculptor_as_it_was():
    s = sweepers.Sculptor(voxel_size=1 / 64)
    s.apply(STROKES[0])
    before, volume = voxels(s.to_pyopenvdb()), s.volume
    # SIGINT, as Ctrl-C in a terminal or a notebook's interrupt sends it, from another thread
    # while the engine works (a pinch at 1/64 takes about a second, the sanitizers' build
    # several): no Python code runs in between that would see it.
    timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        s.apply([STROKES[1], PINCH, STROKES[2]])
    timer.join()
    assert time.monotonic() - started < 10
    assert s.volume == volume and voxels(s.to_pyopenvdb()) == before
    assert len(s.script()["strokes"]) == 1 and s.can_undo and not s.can_redo
    # Python's own handler is back.
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    # The same Sculptor goes on.
    s.apply(PINCH)
    assert s.topology["genus"] == 1


def test_the_engine_releases_the_gil():
    ticks = []
    done = threading.Event()

    def work():
        sweepers.apply(TWISTED, voxel_size=1 / 64)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(1)  # runs only while the apply does not hold the GIL
    t.join()
    assert len(ticks) > 1000


def test_threads_sharing_a_sculptor_take_turns():
    # Two or more threads sculpting one Sculptor crashed or hung (the engine runs without the
    # GIL): each call now waits for the one using it. Three threads apply strokes, two read
    # it meanwhile, and two more sculpt Sculptors of their own.
    shared = sweepers.Sculptor(voxel_size=1 / 32)
    own = [sweepers.Sculptor(voxel_size=1 / 32) for _ in range(2)]
    errors, sculpting = [], threading.Event()

    def guarded(work):
        def run():
            try:
                work()
            except BaseException as e:  # noqa: B036 (any failure fails the test)
                errors.append(e)
        return run

    def sculpt(first):
        for k in range(3):
            shared.apply(STROKES[(first + k) % len(STROKES)])
            sculpting.set()

    def read():
        sculpting.wait()
        for _ in range(10):
            shared.sample(np.zeros((8, 3)))
            assert shared.topology["components"] >= 1 and shared.volume > 0
            shared.can_undo, shared.script()

    def alone(s):
        for stroke in STROKES[:2]:
            s.apply(stroke)

    threads = ([threading.Thread(target=guarded(lambda f=f: sculpt(f))) for f in (0, 3, 7)]
               + [threading.Thread(target=guarded(read)) for _ in range(2)]
               + [threading.Thread(target=guarded(lambda s=s: alone(s))) for s in own])
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=600)
    assert not any(t.is_alive() for t in threads) and errors == []
    # Nine whole strokes, one after another: the session's script replays to its grid.
    script = shared.script()
    assert len(script["strokes"]) == 9
    assert voxels(sweepers.apply(script).to_pyopenvdb()) == voxels(shared.to_pyopenvdb())
    for s in own:
        assert voxels(s.to_pyopenvdb()) == voxels(sweepers.apply(s.script()).to_pyopenvdb())
    # Undo takes back the strokes one call at a time, from any thread.
    undo = [threading.Thread(target=shared.undo) for _ in range(9)]
    for t in undo:
        t.start()
    for t in undo:
        t.join()
    assert shared.script()["strokes"] == [] and not shared.can_undo


def test_an_error_in_the_progress_callbacks_last_call_is_raised():
    calls = []

    def fail_at_the_end(done, total):
        calls.append(done)
        if done == total:
            raise RuntimeError("the last report")

    s = sweepers.Sculptor(voxel_size=1 / 32)
    with pytest.raises(RuntimeError, match="the last report"):
        s.apply(STROKES[0], progress=fail_at_the_end)
    assert calls and s.script()["strokes"] == [] and not s.can_undo
    with pytest.raises(RuntimeError, match="the last report"):
        sweepers.apply(RIGID, voxel_size=1 / 16, progress=fail_at_the_end)


def test_wrong_types_raise_type_error_and_nan_in_a_dict_says_so(tmp_path):
    for call in (lambda: sweepers.apply(RIGID, voxel_size="fine"),
                 lambda: sweepers.Sculptor(voxel_size=[0.1]),
                 lambda: sweepers.Sculptor(half_width="3"),
                 lambda: sweepers.apply(RIGID, voxel_size=True),
                 lambda: sweepers.study(RIGID, ["1/8"], variants=[3], directory=tmp_path)):
        with pytest.raises(TypeError):
            call()
    script = json.load(open(RIGID))
    script["strokes"][0]["tools"][0]["size"] = float("nan")
    with pytest.raises(ValueError, match="not finite"):
        sweepers.apply(script)


def test_a_vdb_with_a_float_voxel_size_is_that_voxel_size(tmp_path):
    # pyopenvdb keeps a voxel size of 0.1 as the float nearest it.
    g = vdb.createLevelSetSphere(radius=0.5, voxelSize=0.1)
    g.name = "surface"
    path = str(tmp_path / "float.vdb")
    vdb.write(path, grids=[g])
    s = sweepers.Sculptor(start=path, voxel_size=0.1)
    assert abs(s.voxel_size - 0.1) < 1e-8
    with pytest.raises(ValueError, match="0.100000001"):
        sweepers.Sculptor(start=path, voxel_size=0.1000001)


def test_work_past_the_limits_is_refused_and_changes_nothing():
    smooth = {"type": "smooth", "tool": {"shape": "ball", "size": 0.3, "falloff": 0.1,
                                         "path": [{"t": [0, 1, 0]}]}}
    s = sweepers.Sculptor(voxel_size=1 / 32)
    before = voxels(s.to_pyopenvdb())
    assert sweepers.limits()["max_work"] == 2e9 and sweepers.limits()["max_memory"] > 0
    sweepers.set_limits(max_work=100)
    try:
        with pytest.raises(sweepers.LimitError, match="smooth dab .* more than the limit of 1"):
            s.apply(smooth)
        assert voxels(s.to_pyopenvdb()) == before and not s.can_undo
        with pytest.raises(sweepers.LimitError):
            sweepers.Sculptor(voxel_size=1 / 32).apply(smooth)
        sweepers.set_limits(max_memory=1e6)
        with pytest.raises(sweepers.LimitError, match="needs about .* over its limit"):
            sweepers.apply(RIGID)
        with pytest.raises(ValueError):
            sweepers.set_limits(max_work=-1)
    finally:
        sweepers.set_limits()
    s.apply(smooth)
    assert s.can_undo and voxels(s.to_pyopenvdb()) != before


def test_a_progress_callback_reading_its_own_sculptor_is_told_not_deadlocked():
    s = sweepers.Sculptor(voxel_size=1 / 32)
    with pytest.raises(RuntimeError, match="busy with a call on this thread"):
        s.apply(STROKES[0], progress=lambda done, total: s.volume)
    assert s.script()["strokes"] == [] and not s.can_undo


def test_generated_histories_give_one_grid_stroke_by_stroke_and_whole(tmp_path):
    # Histories nobody wrote (the test suite's generator, tests/unit/random_history.h): a
    # Sculptor applying them a stroke at a time, sweepers.apply and sweepers-cli apply give the
    # same grid, to the bit.
    subprocess.run([os.environ["SWEEPERS_HISTORY_TESTS"], "--gtest_also_run_disabled_tests",
                    "--gtest_filter=RandomHistories.DISABLED_WriteScripts"],
                   env={**CLI_ENV, "SWEEPERS_HISTORY_SCRIPTS": str(tmp_path),
                        "SWEEPERS_HISTORIES": "3"}, check=True, capture_output=True)
    scripts = sorted(tmp_path.glob("history_*.json"))
    assert len(scripts) == 3
    for path in scripts:
        script = json.load(open(path))
        s = sweepers.Sculptor(start=script.get("start"), voxel_size=script["grid"]["voxel_size"])
        for stroke in script["strokes"]:
            s.apply(stroke)
        cli("apply", str(path), "-o", str(tmp_path / "cli.vdb"), "-q")
        by_cli = voxels(vdb.read(str(tmp_path / "cli.vdb"), "surface"))
        assert voxels(s.to_pyopenvdb()) == by_cli, path.name
        assert voxels(sweepers.apply(str(path)).to_pyopenvdb()) == by_cli, path.name
        print(f"{path.name}: {len(script['strokes'])} strokes, {len(by_cli)} voxels alike")
