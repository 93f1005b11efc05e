"""distance, distance_batch, distance_brute_force, solids (collide/distance with solid=True) and
refit: the CLI's answers bit for bit on the shipped meshes, brute force on small meshes, batches,
and input errors."""
import numpy as np
import pytest
import tightbvh
from conftest import MESHES, pose_matrix, pose_text, rotation, tetrahedron

# B (the knot) in A's (the elephant's) frame: overlapping, a small gap, far apart.
POSES = [
    pose_matrix(rotation([1, 2, 3], 0.7), [0.1, 0.0, 0.05]),
    pose_matrix(rotation([0, 0, 1], 0.3), [1.3, 0.1, 0.0]),
    pose_matrix(np.eye(3), [5.0, 0.0, 0.0]),
]


@pytest.fixture(scope="module")
def trees(elephant, knot):
    return tightbvh.build(elephant), tightbvh.build(knot)


@pytest.mark.parametrize("pose_index", range(len(POSES)))
def test_distance_equals_the_cli_bit_for_bit(cli, elephant, knot, trees, pose_index):
    pose = POSES[pose_index]
    out = cli("distance", MESHES / "elephant.off", MESHES / "knot1.off", "--pose", pose_text(pose))
    d = tightbvh.distance(trees[0], elephant, None, trees[1], knot, pose)
    assert d.distance == out["distance"]
    assert list(d.triangles) == out["triangles"]
    for name in ["point_a", "point_b", "point_a_local", "point_b_local"]:
        assert getattr(d, name).tolist() == out[name]
    assert d.stats == {"node_pairs": out["node_pairs"], "triangle_pairs": out["triangle_pairs"]}
    assert not d.beyond_upper_bound and d.inside == "none"
    assert (d.distance == 0) == (pose_index == 0)


def test_distance_points_lie_on_their_triangles_and_are_that_far_apart(elephant, knot, trees):
    pose = POSES[1]
    d = tightbvh.distance(trees[0], elephant, None, trees[1], knot, pose)
    assert d.distance > 0
    assert np.linalg.norm(d.point_a - d.point_b) == pytest.approx(d.distance, rel=1e-12)
    # point_b_local is B's frame: mapped by pose_b it is point_b (A is at the identity).
    assert pose[:3, :3] @ d.point_b_local + pose[:3, 3] == pytest.approx(d.point_b, abs=1e-12)
    for mesh, index, p in [(elephant, d.triangles[0], d.point_a_local), (knot, d.triangles[1], d.point_b_local)]:
        corners = mesh.vertices[mesh.faces[index]]
        normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
        assert abs(np.dot(p - corners[0], normal / np.linalg.norm(normal))) < 1e-9  # in the triangle's plane


def small_meshes():
    rng = np.random.default_rng(21)
    a = tightbvh.Mesh(rng.uniform(-1, 1, size=(40, 3)), rng.integers(0, 40, size=(60, 3)))
    b = tightbvh.Mesh(rng.uniform(-0.5, 0.5, size=(30, 3)), rng.integers(0, 30, size=(40, 3)))
    return a, b


@pytest.mark.parametrize("fitter", ["aabb", "pca", "approx"])
def test_distance_equals_brute_force_on_small_meshes(fitter):
    a, b = small_meshes()
    ta, tb = tightbvh.build(a, fitter=fitter), tightbvh.build(b, fitter=fitter, leaf_size=3)
    rng = np.random.default_rng(8)
    touching = 0
    for _ in range(12):
        pose = pose_matrix(rotation(rng.normal(size=3), rng.uniform(0, 3)), rng.uniform(-1.6, 1.6, size=3))
        expected = tightbvh.distance_brute_force(a, None, b, pose)
        got = tightbvh.distance(ta, a, None, tb, b, pose)
        assert got.distance == expected.distance
        touching += got.distance == 0
        # Within the requested error, never below the truth.
        loose = tightbvh.distance(ta, a, None, tb, b, pose, relative_error=0.1, absolute_error=0.01)
        assert expected.distance <= loose.distance <= expected.distance * 1.1 + 0.01
    assert 0 < touching < 12  # both answers occur


def test_upper_bound(elephant, knot, trees):
    far = tightbvh.distance(trees[0], elephant, None, trees[1], knot, POSES[2], upper_bound=0.5)
    assert far.beyond_upper_bound and far.distance == 0.5
    assert far.triangles is None and far.point_a is None and far.point_b_local is None
    near = tightbvh.distance(trees[0], elephant, None, trees[1], knot, POSES[1], upper_bound=10.0)
    assert not near.beyond_upper_bound and near.distance < 10.0


def test_distance_batch_equals_single_queries(elephant, knot, trees):
    poses = np.stack(POSES + [pose_matrix(rotation([1, 0, 0], 0.2 * i), [0.4 * i, 0, 0]) for i in range(6)])
    distances, triangles, points_a, points_b = tightbvh.distance_batch(
        trees[0], elephant, None, trees[1], knot, poses, upper_bound=3.0)
    assert distances.shape == (9,) and triangles.shape == (9, 2) and triangles.dtype == np.int64
    assert points_a.shape == points_b.shape == (9, 3)
    for i, pose in enumerate(poses):
        single = tightbvh.distance(trees[0], elephant, None, trees[1], knot, pose, upper_bound=3.0)
        assert distances[i] == single.distance
        if single.beyond_upper_bound:
            assert triangles[i].tolist() == [-1, -1] and np.isnan(points_a[i]).all() and np.isnan(points_b[i]).all()
        else:
            assert triangles[i].tolist() == list(single.triangles)
            assert points_a[i].tolist() == single.point_a.tolist() and points_b[i].tolist() == single.point_b.tolist()
    assert np.isnan(points_a[2]).all()  # POSES[2] is 5 away: beyond the bound of 3
    for threads in [1, 2, 3]:
        again = tightbvh.distance_batch(trees[0], None, None, trees[1], None, poses, upper_bound=3.0, threads=threads)
        assert again[0].tolist() == distances.tolist() and again[1].tolist() == triangles.tolist()


def scaled_tetrahedron(scale, shift):
    vertices, faces = tetrahedron()
    return tightbvh.Mesh(vertices * scale + shift, faces)


def test_solids_report_a_mesh_wholly_inside_another():
    outer = scaled_tetrahedron(4.0, [-1.0, -1.0, -1.0])
    inner = scaled_tetrahedron(0.5, [0.0, 0.0, 0.0])
    to, ti = tightbvh.build(outer), tightbvh.build(inner)
    surfaces = tightbvh.collide(to, outer, None, ti, inner, None)
    assert not surfaces and surfaces.inside == "none"  # the surfaces do not touch
    solid = tightbvh.collide(to, outer, None, ti, inner, None, solid=True)
    assert solid and solid.inside == "b_in_a" and len(solid.pairs) == 0
    assert tightbvh.collide_brute_force(outer, None, inner, None, solid=True).inside == "b_in_a"
    assert tightbvh.collide(ti, inner, None, to, outer, None, solid=True).inside == "a_in_b"
    hits, _ = tightbvh.collide_batch(to, outer, None, ti, inner, [np.eye(4), pose_matrix(np.eye(3), [9, 0, 0])],
                                     solid=True)
    assert hits.tolist() == [True, False]
    d = tightbvh.distance(to, outer, None, ti, inner, None, solid=True)
    assert d.distance == 0 and d.inside == "b_in_a" and d.triangles is None
    assert d.point_a.tolist() == d.point_b.tolist()
    assert tightbvh.distance(to, outer, None, ti, inner, None).distance > 0  # as surfaces
    assert tightbvh.distance_brute_force(outer, None, inner, None, solid=True).inside == "b_in_a"


def test_solid_on_an_open_mesh_is_a_value_error():
    vertices, faces = tetrahedron()
    open_mesh = tightbvh.Mesh(vertices, faces[:3])  # one face missing: 3 boundary edges
    closed = tightbvh.Mesh(vertices, faces)
    to, tc = tightbvh.build(open_mesh), tightbvh.build(closed)
    with pytest.raises(ValueError, match="boundary edge"):
        tightbvh.collide(to, open_mesh, None, tc, closed, None, solid=True)
    with pytest.raises(ValueError, match="boundary edge"):
        tightbvh.distance(tc, closed, None, to, open_mesh, None, solid=True)


def test_signed_distance_is_minus_the_deepest_vertex():
    # A small tetrahedron sunk into a large one: inner corners inside the outer solid; the
    # answer is minus the deepest one's distance to the outer surface, with that corner and its
    # closest point as the witnesses.
    outer = scaled_tetrahedron(4.0, [-1.0, -1.0, -1.0])
    inner = scaled_tetrahedron(1.0, [-1.5, 0.2, 0.3])  # partly inside, partly out through x = -1
    to, ti = tightbvh.build(outer), tightbvh.build(inner)
    d = tightbvh.distance(to, outer, None, ti, inner, None, signed_distance=True)
    assert d.distance < 0 and d.deepest == "b_in_a" and d.triangles is None
    assert not d.penetration_lower_bound_is_zero
    assert d.point_b.tolist() == inner.vertices[d.deepest_vertex].tolist()
    assert np.linalg.norm(d.point_a - d.point_b) == pytest.approx(-d.distance, rel=1e-12)
    # Every inner vertex inside the outer solid is at most that deep (the point queries agree).
    model = tightbvh.Model(outer)
    depths = -model.signed_distance(inner.vertices)
    assert -d.distance == pytest.approx(depths.max(), rel=1e-12)
    brute = tightbvh.distance_brute_force(outer, None, inner, None, signed_distance=True)
    assert (brute.distance, brute.deepest, brute.deepest_vertex) == (d.distance, d.deepest, d.deepest_vertex)
    distances, triangles, points_a, points_b = tightbvh.distance_batch(
        to, outer, None, ti, inner, [np.eye(4), pose_matrix(np.eye(3), [20, 0, 0])], signed_distance=True)
    assert distances[0] == d.distance and distances[1] > 0
    assert triangles[0].tolist() == [-1, -1] and points_b[0].tolist() == d.point_b.tolist()
    # Swapped: the vertex is A's.
    swapped = tightbvh.distance(ti, inner, None, to, outer, None, signed_distance=True)
    assert swapped.deepest == "a_in_b" and swapped.distance == d.distance


def test_signed_distance_apart_is_the_unsigned_answer():
    outer = scaled_tetrahedron(1.0, [0.0, 0.0, 0.0])
    other = scaled_tetrahedron(1.0, [3.0, 0.5, 0.0])
    to, tb = tightbvh.build(outer), tightbvh.build(other)
    plain = tightbvh.distance(to, outer, None, tb, other, None)
    signed = tightbvh.distance(to, outer, None, tb, other, None, signed_distance=True)
    assert plain.distance > 0 and signed.distance == plain.distance and signed.deepest == "none"
    assert signed.triangles == plain.triangles and signed.point_a.tolist() == plain.point_a.tolist()


def box_mesh(lo, hi):
    """The box [lo, hi] (outward triangles)."""
    corners = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]]
                        for i in range(8)], dtype=np.float64)
    faces = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]], dtype=np.int64)
    return tightbvh.Mesh(corners, faces)


def test_signed_distance_of_crossing_edges_reports_the_curve_length():
    # Two thin boxes crossed like a plus sign: no vertex inside the other solid, so the bound is 0;
    # the surfaces cross along eight segments of length 0.2.
    a = box_mesh([-2, -0.1, -0.1], [2, 0.1, 0.1])
    b = box_mesh([-0.1, -2, -0.2], [0.1, 2, 0.2])
    ta, tb = tightbvh.build(a), tightbvh.build(b)
    d = tightbvh.distance(ta, a, None, tb, b, None, signed_distance=True)
    assert d.distance == 0 and d.penetration_lower_bound_is_zero and d.deepest == "none"
    assert d.curve_length == pytest.approx(1.6, rel=1e-12)
    crossing = tightbvh.collide(ta, a, None, tb, b, None, all_pairs=True, contacts=True)
    assert d.curve_length == pytest.approx(crossing.curve_length, rel=1e-12)
    unsigned = tightbvh.distance(ta, a, None, tb, b, None)
    assert unsigned.curve_length == 0


def test_signed_distance_on_an_open_mesh_is_a_value_error():
    vertices, faces = tetrahedron()
    open_mesh = tightbvh.Mesh(vertices, faces[:3])
    closed = tightbvh.Mesh(vertices, faces)
    with pytest.raises(ValueError, match="mesh B is not closed"):
        tightbvh.distance(tightbvh.build(closed), closed, None, tightbvh.build(open_mesh), open_mesh, None,
                          signed_distance=True)


def test_refit_follows_the_moved_vertices(elephant, knot, trees):
    bent = elephant.vertices.copy()
    bent[:, 1] += 0.3 * np.sin(3.0 * bent[:, 0])  # a smooth bend
    moved = tightbvh.Mesh(bent, elephant.faces)
    for fitter in ["pca", "auto"]:
        refitted = tightbvh.refit(trees[0], moved, fitter=fitter)
        assert refitted.mesh is moved and refitted.validate()  # every box contains its triangles
        assert refitted.triangle_order.tolist() == trees[0].triangle_order.tolist()  # same topology
        assert not trees[0].validate(moved)  # the old boxes do not contain the bent mesh
        for pose in POSES[:2]:
            got = tightbvh.collide(refitted, None, None, trees[1], knot, pose, all_pairs=True)
            fresh = tightbvh.collide(tightbvh.build(moved), None, None, trees[1], knot, pose, all_pairs=True)
            assert got.pairs.tolist() == fresh.pairs.tolist()
    assert tightbvh.refit(trees[0], moved, threads=1).nodes()["half_extents"].tolist() == \
        tightbvh.refit(trees[0], moved, threads=2).nodes()["half_extents"].tolist()


def test_input_errors(elephant, knot, trees):
    with pytest.raises(ValueError, match="absolute_error"):
        tightbvh.distance(trees[0], None, None, trees[1], None, None, absolute_error=-1.0)
    with pytest.raises(ValueError, match="relative_error"):
        tightbvh.distance(trees[0], None, None, trees[1], None, None, relative_error=float("nan"))
    with pytest.raises(ValueError, match="upper_bound"):
        tightbvh.distance_batch(trees[0], None, None, trees[1], None, [np.eye(4)], upper_bound=-1.0)
    with pytest.raises(ValueError, match="threads: must be in"):
        tightbvh.distance_batch(trees[0], None, None, trees[1], None, [np.eye(4)], threads=-1)
    with pytest.raises(ValueError):  # tree and mesh do not belong together (the library's InputError)
        tightbvh.distance(trees[0], knot, None, trees[1], knot, None)
    with pytest.raises(ValueError, match="triangle"):  # refit: another face count
        tightbvh.refit(trees[0], knot)
    with pytest.raises(ValueError, match="fitter: unknown fitter"):
        tightbvh.refit(trees[0], elephant, fitter="nope")
