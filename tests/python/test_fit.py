"""fit(): every method and container, against the CLI's `tightbvh fit --json` bit for bit,
containment, known volumes, options and input errors."""
import math

import numpy as np
import pytest
import tightbvh
from conftest import tetrahedron

BOX_METHODS = ["aabb", "pca", "pca-vertex", "diameter", "approx", "approx-snap", "exact", "eberly2015",
               "approx-kernel", "normal-bopt", "dito"]
CONTAINERS = ["ball", "fast-ball", "ellipsoid", "diamond", "dop14", "dop18", "dop26"]


def write_off(path, vertices, faces):
    lines = ["OFF", f"{len(vertices)} {len(faces)} 0"]
    lines += [" ".join(repr(float(x)) for x in v) for v in vertices]
    lines += ["3 " + " ".join(str(int(i)) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def cloud_mesh(tmp_path_factory):
    """200 random points (a skewed blob) as a triangle soup, written as OFF (exact doubles)."""
    rng = np.random.default_rng(7)
    points = rng.normal(size=(200, 3)) @ np.array([[3.0, 0.5, 0.2], [0.0, 1.0, 0.7], [0.0, 0.0, 0.4]])
    faces = np.arange(198)[:, None] + np.array([0, 1, 2])
    path = tmp_path_factory.mktemp("fit") / "cloud.off"
    write_off(path, points, faces)
    return path, tightbvh.load_mesh(path)


def test_fit_methods_lists_box_methods_then_containers():
    assert tightbvh.fit_methods() == BOX_METHODS + CONTAINERS


def assert_same_as_cli(fitted, row):
    assert fitted.volume == row["volume"]
    if "half_extents" in row:  # boxes: axes as columns, the CLI lists the columns
        assert fitted.center.tolist() == row["center"]
        assert fitted.axes.T.tolist() == row["axes"]
        assert fitted.half_extents.tolist() == row["half_extents"]
    elif "radius" in row:
        assert fitted.center.tolist() == row["center"] and fitted.radius == row["radius"]
    elif "radii" in row:
        assert fitted.center.tolist() == row["center"]
        assert fitted.axes.T.tolist() == row["axes"] and fitted.radii.tolist() == row["radii"]
    else:
        assert fitted.directions.tolist() == [s["direction"] for s in row["slabs"]]
        assert fitted.min.tolist() == [s["min"] for s in row["slabs"]]
        assert fitted.max.tolist() == [s["max"] for s in row["slabs"]]


def test_every_method_equals_the_cli_bit_for_bit(cli, cloud_mesh):
    path, mesh = cloud_mesh
    rows = cli("fit", path, "--method", "all")
    assert [r["method"] for r in rows] == BOX_METHODS + CONTAINERS
    for row in rows:
        assert_same_as_cli(tightbvh.fit(mesh, row["method"]), row)


@pytest.mark.parametrize("method", ["approx", "pca", "aabb", "ball", "ellipsoid", "dop26"])
def test_shipped_mesh_equals_the_cli_bit_for_bit(cli, elephant, method):
    from conftest import MESHES

    (row,) = cli("fit", MESHES / "elephant.off", "--method", method)
    assert_same_as_cli(tightbvh.fit(elephant, method), row)


def test_options_equal_the_cli(cli, cloud_mesh):
    path, mesh = cloud_mesh
    (row,) = cli("fit", path, "--method", "approx", "--grid", "5")
    assert_same_as_cli(tightbvh.fit(mesh, "approx", grid=5), row)
    (row,) = cli("fit", path, "--method", "approx", "--epsilon", "0.01")
    assert_same_as_cli(tightbvh.fit(mesh, "approx", epsilon=0.01), row)


@pytest.mark.parametrize("method", BOX_METHODS + CONTAINERS)
def test_containers_contain_the_points(method, cloud_mesh):
    points = cloud_mesh[1].vertices
    fitted = tightbvh.fit(points, method)
    scale = np.abs(points).max()
    assert fitted.contains(points, tolerance=1e-9 * scale).all()
    assert fitted.volume > 0
    if method in BOX_METHODS:
        exact = tightbvh.fit(points, "exact").volume
        assert fitted.volume >= exact * (1 - 1e-12)
        axes = fitted.axes
        np.testing.assert_allclose(axes.T @ axes, np.eye(3), atol=1e-12)
        assert np.linalg.det(axes) > 0


def test_box_corners_and_containment():
    box = tightbvh.fit([[0, 0, 0], [2, 0, 0], [0, 4, 0], [0, 0, 6], [2, 4, 6]], "aabb")
    np.testing.assert_array_equal(box.center, [1, 2, 3])
    np.testing.assert_array_equal(box.half_extents, [1, 2, 3])
    assert box.volume == 48.0
    corners = box.corners()
    assert corners.shape == (8, 3)
    assert sorted(map(tuple, corners.tolist())) == sorted((x, y, z) for x in (0, 2) for y in (0, 4) for z in (0, 6))
    assert box.contains(corners).all()
    assert box.contains([[1, 2, 3], [3, 0, 0]]).tolist() == [True, False]


def test_regular_tetrahedron_has_the_known_minimum_box():
    s = 1 / math.sqrt(3)
    points = s * np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    assert tightbvh.fit(points, "exact").volume == pytest.approx(8 / math.sqrt(27), rel=1e-12)
    # Eberly's 2015 method misses that cube (the known counterexample: docs/algorithms.md,
    # "eberly2015").
    assert tightbvh.fit(points, "eberly2015").volume > 1.5 * 8 / math.sqrt(27)


def test_pca_on_a_mesh_weights_triangles_on_points_it_is_pca_vertex(cloud_mesh):
    mesh = cloud_mesh[1]
    on_points = tightbvh.fit(mesh.vertices, "pca")
    assert on_points.axes.tolist() == tightbvh.fit(mesh.vertices, "pca-vertex").axes.tolist()
    assert tightbvh.fit(mesh, "pca").axes.tolist() != on_points.axes.tolist()


def test_containers_have_their_fields():
    v, _ = tetrahedron()
    ball = tightbvh.fit(v, "ball")
    # The smallest ball is the circumcircle's of the slanted face (it also holds the origin).
    np.testing.assert_allclose(ball.center, [1 / 3, 1 / 3, 1 / 3], atol=1e-12)
    assert ball.radius == pytest.approx(math.sqrt(6) / 3, rel=1e-12)
    assert ball.volume == pytest.approx(4 / 3 * math.pi * ball.radius**3)
    assert tightbvh.fit(v, "fast-ball").radius >= ball.radius
    dop = tightbvh.fit(v, "dop14")
    assert dop.kind == "dop14" and dop.directions.shape == (7, 3) and dop.min.shape == (7,)
    assert dop.volume == pytest.approx(1 / 6, rel=1e-12)  # the DOP of a tetrahedron's corners is itself here
    ellipsoid = tightbvh.fit(v, "ellipsoid", epsilon=1e-6)
    assert ellipsoid.radii.shape == (3,) and ellipsoid.axes.shape == (3, 3)
    # Within (1 + 1e-6) of the minimum, which the default (0.01) one is not below.
    assert ellipsoid.volume <= tightbvh.fit(v, "ellipsoid").volume * (1 + 2e-6)


@pytest.mark.parametrize(
    "args, kwargs, error, message",
    [
        (([[0, 0, 0]], "nope"), {}, ValueError, "fit: unknown method 'nope' \\(expected aabb, pca, .* or dop26\\)"),
        ((np.zeros((0, 3)),), {}, ValueError, "fit: empty point set"),
        (([[0, 0, np.nan]],), {}, ValueError, "points: row 0 has a non-finite"),
        ((np.zeros((3, 2)),), {}, ValueError, r"points: expected shape \(N, 3\)"),
        (("abc",), {}, TypeError, "points: expected real numbers"),
        (([[0, 0, 0]],), {"grid": 0}, ValueError, r"fit: grid must be in \[1, 64\], got 0"),
        (([[0, 0, 0]],), {"grid": 1.5}, TypeError, "fit: grid must be an integer"),
        (([[0, 0, 0]],), {"grid": 2, "epsilon": 0.1}, ValueError, "grid and epsilon exclude each other"),
        (([[0, 0, 0]],), {"epsilon": -1}, ValueError, "fit: epsilon must be a positive finite number"),
        (([[0, 0, 0]],), {"epsilon": "x"}, TypeError, "fit: epsilon must be a number"),
        (([[0, 0, 0]],), {"improve": 1}, TypeError, "fit: improve must be True or False"),
        (([[0, 0, 0]],), {"gird": 3}, TypeError, "fit: method 'approx' takes no option 'gird'"),
        (([[0, 0, 0]], "ball"), {"grid": 3}, TypeError, "fit: method 'ball' takes no option 'grid'"),
        (([[0, 0, 0]], "ellipsoid"), {"epsilon": 0}, ValueError, "epsilon must be a positive finite number"),
    ],
)
def test_fit_errors(args, kwargs, error, message):
    with pytest.raises(error, match=message):
        tightbvh.fit(*args, **kwargs)
