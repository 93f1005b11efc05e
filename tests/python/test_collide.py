"""collide, collide_batch, collide_brute_force: the CLI's answers bit for bit on the shipped
meshes, brute force on small meshes, the pose forms, batches, the GIL, and input errors; collide
and distance on two Models: the trees' answers."""
import threading
import time

import numpy as np
import pytest
import tightbvh
from conftest import MESHES, pose_matrix, pose_text, rotation, tetrahedron

# B (the knot) in A's (the elephant's) frame: deep overlap, grazing, apart.
POSES = [
    pose_matrix(rotation([1, 2, 3], 0.7), [0.1, 0.0, 0.05]),
    pose_matrix(rotation([0, 0, 1], 0.3), [0.9, 0.1, 0.0]),
    pose_matrix(np.eye(3), [5.0, 0.0, 0.0]),
]


@pytest.fixture(scope="module")
def trees(elephant, knot):
    return tightbvh.build(elephant), tightbvh.build(knot)


@pytest.mark.parametrize("pose_index", range(len(POSES)))
@pytest.mark.parametrize("all_pairs", [False, True])
def test_collide_equals_the_cli_bit_for_bit(cli, elephant, knot, trees, pose_index, all_pairs):
    pose = POSES[pose_index]
    flags = ["--all-pairs"] if all_pairs else []
    out = cli("collide", MESHES / "elephant.off", MESHES / "knot1.off", "--pose", pose_text(pose), *flags)
    result = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=all_pairs)
    assert result.hit == out["hit"] == bool(result)
    assert result.pairs.tolist() == out["pairs"]
    assert result.stats == {"box_tests": out["box_tests"], "triangle_tests": out["triangle_tests"]}
    if pose_index == 0:
        assert result.hit and (not all_pairs or len(result.pairs) > 100)


@pytest.fixture(scope="module")
def models(elephant, knot):
    return tightbvh.Model(elephant), tightbvh.Model(knot)


@pytest.mark.parametrize("pose_index", range(len(POSES)))
def test_collide_and_distance_on_models_equal_the_trees(elephant, knot, trees, models, pose_index):
    pose = POSES[pose_index]
    on_trees = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=True)
    on_models = tightbvh.collide(models[0], None, models[1], pose, all_pairs=True)
    assert on_models.pairs.tolist() == on_trees.pairs.tolist()
    assert on_models.hit == on_trees.hit == tightbvh.collide(models[0], None, models[1], pose).hit
    within = tightbvh.collide(models[0], None, models[1], pose, all_pairs=True, margin=0.01)
    expected = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=True, margin=0.01)
    assert within.pairs.tolist() == expected.pairs.tolist()
    gap = tightbvh.distance(models[0], np.eye(4), models[1], pose)
    assert gap.distance == tightbvh.distance(trees[0], elephant, None, trees[1], knot, pose).distance
    assert (gap.distance == 0.0) == on_trees.hit


def test_model_queries_input_errors(models, trees):
    with pytest.raises(ValueError, match="pose_b: rotation is not orthonormal"):
        tightbvh.collide(models[0], None, models[1], np.diag([2.0, 1, 1, 1]))
    with pytest.raises(TypeError):
        tightbvh.collide(models[0], None, trees[1], None)  # a Model and a Tree do not mix
    with pytest.raises(TypeError):
        tightbvh.distance(models[0], None, "knot", None)
    with pytest.raises(ValueError, match="relative_error"):
        tightbvh.distance(models[0], None, models[1], None, relative_error=-1.0)


def small_meshes():
    rng = np.random.default_rng(11)
    a = tightbvh.Mesh(rng.uniform(-1, 1, size=(40, 3)), rng.integers(0, 40, size=(60, 3)))
    b = tightbvh.Mesh(rng.uniform(-1, 1, size=(30, 3)), rng.integers(0, 30, size=(50, 3)))
    return a, b


@pytest.mark.parametrize("fitter", ["aabb", "pca", "approx", "exact"])
def test_collide_equals_brute_force_on_small_meshes(fitter):
    a, b = small_meshes()
    tree_a = tightbvh.build(a, fitter=fitter)
    tree_b = tightbvh.build(b, fitter=fitter, leaf_size=3)
    rng = np.random.default_rng(5)
    hits = 0
    for i in range(12):
        pose_b = pose_matrix(rotation(rng.normal(size=3), rng.uniform(0, 3)), rng.uniform(-1.5, 1.5, size=3))
        expected = tightbvh.collide_brute_force(a, None, b, pose_b, all_pairs=True)
        result = tightbvh.collide(tree_a, a, None, tree_b, b, pose_b, all_pairs=True)
        assert result.pairs.tolist() == expected.pairs.tolist()
        first = tightbvh.collide(tree_a, a, None, tree_b, b, pose_b)
        assert first.hit == expected.hit and len(first.pairs) == int(expected.hit)
        if first.hit:
            assert first.pairs[0].tolist() in expected.pairs.tolist()
        hits += expected.hit
    assert 0 < hits < 12  # both answers occur


def test_pose_forms_agree(elephant, knot, trees):
    m = POSES[0]
    expected = tightbvh.collide(trees[0], elephant, None, trees[1], knot, m, all_pairs=True).pairs.tolist()
    for pose_b in [m.tolist(), (m[:3, :3], m[:3, 3]), [m[:3, :3].tolist(), m[:3, 3].tolist()], np.asfortranarray(m)]:
        got = tightbvh.collide(trees[0], elephant, np.eye(4), trees[1], knot, pose_b, all_pairs=True)
        assert got.pairs.tolist() == expected
    # A moved too: only the relative pose pa^-1 pb matters, here exactly (R, (t_m + t) - t) in both
    t = np.array([1.0, 2.0, 3.0])
    moved = tightbvh.collide(trees[0], None, (np.eye(3), t), trees[1], None, (m[:3, :3], m[:3, 3] + t), all_pairs=True)
    shifted = tightbvh.collide(trees[0], None, None, trees[1], None, (m[:3, :3], (m[:3, 3] + t) - t), all_pairs=True)
    assert moved.pairs.tolist() == shifted.pairs.tolist()


def test_result_fields(elephant, knot, trees):
    result = tightbvh.collide(trees[0], elephant, None, trees[1], knot, POSES[0], all_pairs=True)
    assert result.pairs.dtype == np.uint32 and result.pairs.ndim == 2 and result.pairs.shape[1] == 2
    pairs = [tuple(p) for p in result.pairs.tolist()]
    assert pairs == sorted(set(pairs))
    assert result.pairs[:, 0].max() < elephant.face_count and result.pairs[:, 1].max() < knot.face_count
    apart = tightbvh.collide(trees[0], elephant, None, trees[1], knot, POSES[2], all_pairs=True)
    assert not apart and apart.pairs.shape == (0, 2)


def batch_poses(n, seed=2):
    rng = np.random.default_rng(seed)
    poses = np.empty((n, 4, 4))
    for i in range(n):
        poses[i] = pose_matrix(rotation(rng.normal(size=3), rng.uniform(0, 3)), rng.uniform(-0.6, 0.6, size=3))
    return poses


@pytest.mark.parametrize("all_pairs", [False, True])
def test_collide_batch_equals_single_queries(elephant, knot, trees, all_pairs):
    poses = batch_poses(24)
    hits, counts = tightbvh.collide_batch(trees[0], elephant, None, trees[1], knot, poses, all_pairs=all_pairs)
    assert hits.dtype == np.bool_ and counts.dtype == np.int64 and hits.shape == counts.shape == (24,)
    for i, pose in enumerate(poses):
        single = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=all_pairs)
        assert hits[i] == single.hit and counts[i] == len(single.pairs)
    assert 0 < hits.sum() < 24
    for threads in [1, 2, 5]:
        again = tightbvh.collide_batch(trees[0], elephant, None, trees[1], knot, poses, all_pairs, threads)
        assert again[0].tolist() == hits.tolist() and again[1].tolist() == counts.tolist()
    rs_ts = (poses[:, :3, :3], poses[:, :3, 3])
    assert tightbvh.collide_batch(trees[0], None, None, trees[1], None, rs_ts, all_pairs)[1].tolist() == counts.tolist()
    two = [poses[0].tolist(), poses[1].tolist()]  # a list of two 4x4 matrices, not a (Rs, ts) pair
    assert tightbvh.collide_batch(trees[0], None, None, trees[1], None, two, all_pairs)[1].tolist() == counts[:2].tolist()
    empty = tightbvh.collide_batch(trees[0], None, None, trees[1], None, np.zeros((0, 4, 4)))
    assert empty[0].shape == (0,) and empty[1].shape == (0,)


def test_collide_batch_releases_the_gil(trees):
    poses = batch_poses(400, seed=9)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.0005)

    counter = threading.Thread(target=count)
    counter.start()
    time.sleep(0.01)
    before = len(ticks)
    # ~0.1 s of all_pairs queries on one thread: the counter ticks every ~0.5 ms meanwhile, or never
    # if the GIL were held.
    tightbvh.collide_batch(trees[0], None, None, trees[1], None, poses, all_pairs=True, threads=1)
    during = len(ticks) - before
    stop.set()
    counter.join()
    assert during >= 5


BAD_POSES = [
    (np.eye(3), ValueError, r"pose_b: expected shape \(4, 4\) or a \(R, t\) pair, got \(3, 3\)"),
    ("x", TypeError, "pose_b: expected real numbers"),
    (np.diag([2.0, 1, 1, 1]), ValueError, "pose_b: rotation is not orthonormal"),
    (np.diag([-1.0, 1, 1, 1]), ValueError, "pose_b: rotation has determinant -1"),
    (np.full((4, 4), np.nan), ValueError, "pose_b: the matrix has a non-finite value"),
    (np.vstack([np.eye(4)[:3], [0, 0, 1, 1]]), ValueError, r"last row of a 4x4 pose must be \(0, 0, 0, 1\)"),
    ((np.eye(3), [0, 0]), ValueError, r"pose_b\[1\]: expected shape \(3,\)"),
    ((np.eye(3), [0, np.inf, 0]), ValueError, "pose_b: the translation has a non-finite value"),
]


@pytest.mark.parametrize("pose, error, message", BAD_POSES)
def test_pose_errors(pose, error, message):
    mesh = tightbvh.Mesh(*tetrahedron())
    tree = tightbvh.build(mesh)
    with pytest.raises(error, match=message):
        tightbvh.collide(tree, mesh, None, tree, mesh, pose)


def test_query_input_errors(elephant, knot, trees):
    with pytest.raises(ValueError, match=r"poses: expected shape \(N, 4, 4\)"):
        tightbvh.collide_batch(trees[0], None, None, trees[1], None, np.eye(4))
    bad = batch_poses(3)
    bad[2, 0, 0] = 3.0
    with pytest.raises(ValueError, match=r"poses\[2\]: rotation is not orthonormal"):
        tightbvh.collide_batch(trees[0], None, None, trees[1], None, bad)
    with pytest.raises(ValueError, match=r"poses\[1\]: expected shape \(N, 3\) with N = 3"):
        tightbvh.collide_batch(trees[0], None, None, trees[1], None, (bad[:, :3, :3], bad[:2, :3, 3]))
    with pytest.raises(ValueError, match="threads: must be in"):
        tightbvh.collide_batch(trees[0], None, None, trees[1], None, bad[:2], threads=-2)
    with pytest.raises(ValueError):  # the library's InputError: tree and mesh do not belong together
        tightbvh.collide(trees[0], knot, None, trees[1], knot, None)
    with pytest.raises(TypeError):
        tightbvh.collide(elephant, elephant, None, trees[1], knot, None)
    with pytest.raises(TypeError, match="mesh_b: expected a tightbvh.Mesh"):
        tightbvh.collide(trees[0], None, None, trees[1], "knot", None)


def test_margin_equals_brute_force_and_contains_the_touching_pairs():
    a, b = small_meshes()
    ta, tb = tightbvh.build(a), tightbvh.build(b)
    pose = pose_matrix(rotation([0, 1, 1], 0.4), [0.3, 0.0, 0.0])
    touching = tightbvh.collide(ta, a, None, tb, b, pose, all_pairs=True)
    near = tightbvh.collide(ta, a, None, tb, b, pose, all_pairs=True, margin=0.05)
    reference = tightbvh.collide_brute_force(a, None, b, pose, all_pairs=True, margin=0.05)
    assert near.pairs.tolist() == reference.pairs.tolist()
    assert set(map(tuple, touching.pairs.tolist())) <= set(map(tuple, near.pairs.tolist()))
    assert len(near.pairs) > len(touching.pairs)
    hits, counts = tightbvh.collide_batch(ta, a, None, tb, b, [pose], all_pairs=True, margin=0.05)
    assert hits.tolist() == [True] and counts.tolist() == [len(near.pairs)]
    with pytest.raises(ValueError, match="margin"):
        tightbvh.collide(ta, a, None, tb, b, pose, margin=-1.0)


def point_triangle_distance(p, t):
    """Distance from p to the closed triangle t (3, 3): the closest point of the plane if it is
    inside, else of the three edges."""
    a, b, c = t
    n = np.cross(b - a, c - a)
    q = p - np.dot(p - a, n) / np.dot(n, n) * n
    m = np.array([b - a, c - a]).T
    u, v = np.linalg.lstsq(m, q - a, rcond=None)[0]
    if u >= 0 and v >= 0 and u + v <= 1:
        return np.linalg.norm(p - q)

    def seg(x, y):
        s = np.clip(np.dot(p - x, y - x) / np.dot(y - x, y - x), 0, 1)
        return np.linalg.norm(p - (x + s * (y - x)))

    return min(seg(a, b), seg(b, c), seg(c, a))


def test_contacts_arrays(elephant, knot, trees):
    pose = POSES[0]
    result = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=True, contacts=True)
    plain = tightbvh.collide(trees[0], elephant, None, trees[1], knot, pose, all_pairs=True)
    assert plain.segments is None and plain.curve_length is None
    k = len(result.pairs)
    assert result.pairs.tolist() == plain.pairs.tolist() and k > 100
    assert result.segments.shape == (k, 2, 3) and result.segments.dtype == np.float64
    assert result.normals_a.shape == (k, 3) and result.normals_b.shape == (k, 3)
    assert result.kind.shape == (k,) and result.kind.dtype == np.uint8 and result.coplanar.shape == (k,)
    assert tightbvh.CONTACT_KINDS[2] == "segment"
    seg = result.kind == 2
    assert seg.sum() > k // 2
    lengths = np.linalg.norm(result.segments[:, 1] - result.segments[:, 0], axis=1)
    assert result.curve_length == pytest.approx(lengths[seg].sum(), rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(result.normals_a, axis=1), 1.0, rtol=1e-12)
    # Each contact lies on both of its triangles (world frame: A at the identity, B at `pose`).
    va, ta = elephant.vertices, elephant.faces
    vb = knot.vertices @ pose[:3, :3].T + pose[:3, 3]
    tb = knot.faces
    for row in range(0, k, max(1, k // 50)):
        ia, ib = result.pairs[row]
        for p in result.segments[row]:
            assert point_triangle_distance(p, va[ta[ia]]) < 1e-9
            assert point_triangle_distance(p, vb[tb[ib]]) < 1e-9
    # The brute force gives the same contacts; pickling keeps them.
    brute = tightbvh.collide_brute_force(tightbvh.Mesh(va, ta[:300]), None, knot, pose, all_pairs=True, contacts=True)
    mine = tightbvh.collide(tightbvh.build(tightbvh.Mesh(va, ta[:300])), None, None, trees[1], knot, pose,
                            all_pairs=True, contacts=True)
    assert len(brute.pairs) > 0
    np.testing.assert_array_equal(brute.segments, mine.segments)
    import pickle

    again = pickle.loads(pickle.dumps(result))
    np.testing.assert_array_equal(again.segments, result.segments)
    assert again.curve_length == result.curve_length


def test_contacts_coplanar_polygon_and_errors():
    square = tightbvh.Mesh(np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0.0]]), np.array([[0, 1, 2]]))
    tree = tightbvh.build(square)
    result = tightbvh.collide(tree, None, None, tree, None, pose_matrix(np.eye(3), [0.5, 0.5, 0]), all_pairs=True,
                              contacts=True)
    assert result.kind.tolist() == [3] and result.coplanar.tolist() == [True]
    assert np.isnan(result.segments).all() and result.curve_length == 0.0
    assert result.polygons[0].shape[1] == 3 and len(result.polygons[0]) >= 3
    with pytest.raises(ValueError, match="contacts"):
        tightbvh.collide(tree, None, None, tree, None, None, contacts=True)
    with pytest.raises(ValueError, match="contacts"):
        tightbvh.collide(tree, None, None, tree, None, None, all_pairs=True, margin=0.1, contacts=True)
