"""Model.closest_points, signed_distance and contains: against a brute force in NumPy (closest
points on every triangle, the winding number for the sign) on small meshes, shapes and dtypes,
poses, max_distance, thread counts and input errors."""
import numpy as np
import pytest
import tightbvh
from conftest import MESHES, pose_matrix, rotation, tetrahedron


def torus(big_r=1.0, small_r=0.35, n=16, k=10):
    """A closed, outward torus around the z axis."""
    u = 2 * np.pi * np.arange(n)[:, None] / n
    v = 2 * np.pi * np.arange(k)[None, :] / k
    x = (big_r + small_r * np.cos(v)) * np.cos(u)
    y = (big_r + small_r * np.cos(v)) * np.sin(u)
    z = small_r * np.sin(v) * np.ones_like(u)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(k), indexing="ij")
    at = lambda a, b: (a % n) * k + (b % k)  # noqa: E731
    faces = np.concatenate([
        np.stack([at(i, j), at(i + 1, j), at(i + 1, j + 1)], axis=-1).reshape(-1, 3),
        np.stack([at(i, j), at(i + 1, j + 1), at(i, j + 1)], axis=-1).reshape(-1, 3),
    ])
    return vertices, faces


def segment_closest(p, a, b):
    """Closest points of segments ab (T, 3) to points p (N, 1, 3): (N, T, 3)."""
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ntj,tj->nt", p - a, d) / np.where(dd > 0, dd, 1.0)
    t = np.clip(np.where(dd > 0, t, 0.0), 0.0, 1.0)
    return a + t[..., None] * d


def brute_closest(vertices, faces, points):
    """Distance (N, T) from every point to every closed triangle: the projection when inside,
    else the nearest point of the three edges."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    p = points[:, None, :]
    n = np.cross(b - a, c - a)
    nn = np.einsum("ij,ij->i", n, n)
    dist = np.einsum("ntj,tj->nt", p - a, n) / np.sqrt(np.where(nn > 0, nn, 1.0))
    proj = p - dist[..., None] * n / np.sqrt(np.where(nn > 0, nn, 1.0))[:, None]
    inside = nn > 0
    for u, w in ((a, b), (b, c), (c, a)):
        inside = inside & (np.einsum("ntj,tj->nt", np.cross(w - u, proj - u), n) > 0)
    best = np.where(inside, np.abs(dist), np.inf)
    for u, w in ((a, b), (b, c), (c, a)):
        best = np.minimum(best, np.linalg.norm(p - segment_closest(p, u, w), axis=-1))
    return best


def winding_number(vertices, faces, points):
    """The generalised winding number (Van Oosterom & Strackee's solid angles over 4 pi)."""
    a, b, c = (vertices[faces[:, k]][None] - points[:, None] for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
    det = np.einsum("ntj,ntj->nt", a, np.cross(b, c))
    dots = la * lb * lc + np.einsum("ntj,ntj->nt", a, b) * lc + np.einsum("ntj,ntj->nt", b, c) * la + \
        np.einsum("ntj,ntj->nt", c, a) * lb
    return (2 * np.arctan2(det, dots)).sum(axis=1) / (4 * np.pi)


@pytest.fixture(scope="module")
def torus_model():
    vertices, faces = torus()
    return tightbvh.Model(tightbvh.Mesh(vertices, faces)), vertices, faces


def sample(vertices, count, seed):
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    pad = 0.3 * (hi - lo)
    return rng.uniform(lo - pad, hi + pad, (count, 3))


def test_closest_points_equal_brute_force_with_shapes_and_dtypes(torus_model):
    model, vertices, faces = torus_model
    points = sample(vertices, 300, 1)
    closest, distance, triangle = model.closest_points(points)
    assert closest.shape == (300, 3) and closest.dtype == np.float64
    assert distance.shape == (300,) and distance.dtype == np.float64
    assert triangle.shape == (300,) and triangle.dtype == np.int64
    brute = brute_closest(vertices, faces, points)
    np.testing.assert_allclose(distance, brute.min(axis=1), rtol=1e-12, atol=1e-15)
    # The triangle reported is at that distance, and the point is that far from the query.
    np.testing.assert_allclose(brute[np.arange(300), triangle], distance, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(points - closest, axis=1), distance, rtol=1e-12, atol=1e-15)


def test_barycentric_coordinates_reconstruct_the_closest_point(torus_model):
    model, vertices, faces = torus_model
    points = sample(vertices, 100, 2)
    closest, distance, triangle, bary = model.closest_points(points, return_barycentric=True)
    assert bary.shape == (100, 3)
    corners = vertices[faces[triangle]]  # (N, 3 corners, 3)
    np.testing.assert_allclose(np.einsum("nk,nkj->nj", bary, corners), closest, atol=1e-12)
    np.testing.assert_allclose(bary.sum(axis=1), 1.0, atol=1e-12)
    assert (bary >= 0).all()


def test_transform_moves_the_mesh(torus_model):
    model, vertices, faces = torus_model
    pose = pose_matrix(rotation([1, 2, 3], 0.8), [2.0, -1.0, 0.5])
    local = sample(vertices, 100, 3)
    world = local @ pose[:3, :3].T + pose[:3, 3]
    closest, distance, triangle = model.closest_points(world, transform=pose)
    _, expect, expect_triangle = model.closest_points(local)
    np.testing.assert_allclose(distance, expect, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(closest, model.closest_points(local)[0] @ pose[:3, :3].T + pose[:3, 3], atol=1e-12)
    signed = model.signed_distance(world, transform=pose)
    np.testing.assert_allclose(np.abs(signed), distance, rtol=1e-12, atol=1e-14)


def test_signed_distance_is_negative_inside_and_contains_agrees(torus_model):
    model, vertices, faces = torus_model
    points = sample(vertices, 400, 4)
    signed = model.signed_distance(points)
    assert signed.shape == (400,) and signed.dtype == np.float64
    inside = model.contains(points)
    assert inside.shape == (400,) and inside.dtype == np.bool_
    inside2, on_surface = model.contains(points, return_on_surface=True)
    assert (inside2 == inside).all() and not on_surface.any()
    winding = winding_number(vertices, faces, points)
    away = np.abs(signed) > 1e-9
    assert ((winding[away] > 0.5) == inside[away]).all()
    assert ((signed < 0) == inside).all()
    assert 0 < inside.sum() < 400
    np.testing.assert_array_equal(np.abs(signed), model.closest_points(points)[1])


def test_points_on_the_surface():
    vertices, faces = tetrahedron()
    model = tightbvh.Model(tightbvh.Mesh(vertices, faces))
    points = np.array([[0.2, 0.2, 0.0], [0.1, 0.1, 0.1], [2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    inside, on_surface = model.contains(points, return_on_surface=True)
    assert inside.tolist() == [False, True, False, False]
    assert on_surface.tolist() == [True, False, False, True]
    signed = model.signed_distance(points)
    assert signed[0] == 0.0 and signed[3] == 0.0 and signed[1] == pytest.approx(-0.1) and signed[2] == 1.0


def test_max_distance_and_threads(torus_model):
    model, vertices, _ = torus_model
    points = sample(vertices, 500, 5)
    closest, distance, triangle = model.closest_points(points, max_distance=0.1)
    full = model.closest_points(points)[1]
    far = full >= 0.1
    assert far.any() and (~far).any()
    assert (triangle[far] == -1).all() and (distance[far] == 0.1).all()
    np.testing.assert_array_equal(closest[far], points[far])
    np.testing.assert_array_equal(distance[~far], full[~far])
    for threads in (1, 2, 3):
        for a, b in zip(model.closest_points(points, threads=threads), model.closest_points(points)):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(model.signed_distance(points, threads=threads), model.signed_distance(points))
        np.testing.assert_array_equal(model.contains(points, threads=threads), model.contains(points))


def test_empty_and_float32_and_list_input(torus_model):
    model, vertices, _ = torus_model
    closest, distance, triangle = model.closest_points(np.zeros((0, 3)))
    assert closest.shape == (0, 3) and distance.shape == (0,) and triangle.shape == (0,)
    points = sample(vertices, 10, 6)
    a = model.closest_points(points.astype(np.float32))[1]
    b = model.closest_points(points.astype(np.float32).astype(np.float64).tolist())[1]
    np.testing.assert_array_equal(a, b)


def test_bad_input(torus_model):
    model, _, _ = torus_model
    with pytest.raises(ValueError, match="points"):
        model.closest_points(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="row 1 has a non-finite"):
        model.signed_distance(np.array([[0.0, 0, 0], [np.nan, 0, 0]]))
    with pytest.raises(TypeError, match="points"):
        model.contains(np.array([["a", "b", "c"]]))
    with pytest.raises(ValueError, match="max_distance"):
        model.closest_points(np.zeros((1, 3)), max_distance=-1.0)
    with pytest.raises(ValueError, match="transform"):
        model.closest_points(np.zeros((1, 3)), transform=np.ones((4, 4)))
    with pytest.raises(TypeError, match="threads"):
        model.closest_points(np.zeros((1, 3)), threads=1.5)
    # An open mesh: closest points work, the sign and contains say why not.
    vertices, faces = tetrahedron()
    open_model = tightbvh.Model(tightbvh.Mesh(vertices, faces[:3]))
    assert open_model.closest_points(np.zeros((1, 3)))[1][0] == 0.0
    with pytest.raises(ValueError, match="not closed: .*boundary edges"):
        open_model.signed_distance(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="not closed"):
        open_model.contains(np.zeros((1, 3)))


def test_shipped_mesh_against_brute_force_sample():
    model = tightbvh.Model(MESHES / "knot1.off")
    vertices, faces = model.mesh.vertices, model.mesh.faces
    points = sample(vertices, 40, 7)
    distance = model.closest_points(points)[1]
    np.testing.assert_allclose(distance, brute_closest(vertices, faces, points).min(axis=1), rtol=1e-12, atol=1e-15)
