"""Objects that travel: every class of the module pickles (protocol 2 and up), copies and
deep-copies; what comes back is the same bit for bit and answers every query the same. Malformed
states are ValueError or TypeError, never a crash."""
import copy
import copyreg
import pickle

import numpy as np
import pytest
import tightbvh
from conftest import pose_matrix, rotation, tetrahedron

PROTOCOLS = range(pickle.HIGHEST_PROTOCOL + 1)  # 0 and 1 too (see reduce_ex in python/src/state.hpp)
COPIES = {
    **{f"pickle{p}": (lambda x, p=p: pickle.loads(pickle.dumps(x, protocol=p))) for p in PROTOCOLS},
    "copy": copy.copy,
    "deepcopy": copy.deepcopy,
}

# The knot in the elephant's frame: deep overlap, grazing, apart.
POSES = [
    pose_matrix(rotation([1, 2, 3], 0.7), [0.1, 0.0, 0.05]),
    pose_matrix(rotation([0, 0, 1], 0.3), [0.9, 0.1, 0.0]),
    pose_matrix(rotation([1, -1, 0], 2.0), [0.3, 0.4, -0.2]),
    pose_matrix(np.eye(3), [5.0, 0.0, 0.0]),
]


def same_bits(a, b):
    """Arrays (or numbers) equal bit for bit: dtype, shape and every byte (-0.0 and NaN too)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def fields(obj):
    """Every public field of a result or container, by class."""
    names = {
        tightbvh.Result: ["hit", "pairs", "stats", "inside"],
        tightbvh.Distance: ["distance", "beyond_upper_bound", "triangles", "point_a", "point_b",
                            "point_a_local", "point_b_local", "inside", "deepest", "deepest_vertex",
                            "penetration_lower_bound_is_zero", "curve_length", "stats"],
        tightbvh.Box: ["center", "axes", "half_extents", "volume"],
        tightbvh.Ball: ["center", "radius", "volume"],
        tightbvh.Ellipsoid: ["center", "axes", "radii", "volume"],
        tightbvh.Dop: ["kind", "directions", "min", "max", "volume"],
        tightbvh.TreeCheck: ["ok", "errors"],
    }[type(obj)]
    return {name: getattr(obj, name) for name in names}


def assert_same(a, b):
    assert type(a) is type(b)
    fa, fb = fields(a), fields(b)
    for name in fa:
        if isinstance(fa[name], np.ndarray) or isinstance(fa[name], float):
            assert same_bits(fa[name], fb[name]), name
        else:
            assert fa[name] == fb[name], name


@pytest.mark.parametrize("how", COPIES)
def test_mesh_round_trip_keeps_every_bit(how):
    vertices, faces = tetrahedron()
    vertices = vertices.copy()
    vertices[0] = [-0.0, 5e-324, 1.0 / 3.0]  # negative zero, a subnormal, a repeating binary fraction
    mesh = tightbvh.Mesh(vertices, faces)
    back = COPIES[how](mesh)
    assert back is not mesh
    assert same_bits(back.vertices, mesh.vertices) and same_bits(back.faces, mesh.faces)
    assert back.faces.dtype == np.uint32 and not back.vertices.flags.writeable


@pytest.fixture(scope="module", params=["pca", "approx", "auto"])
def built(request, elephant, knot):
    return tightbvh.build(elephant, fitter=request.param), tightbvh.build(knot, fitter=request.param)


def answers(tree_a, tree_b):
    """Every query on every pose, with the trees' own meshes."""
    out = []
    for pose in POSES:
        out.append(tightbvh.collide(tree_a, None, None, tree_b, None, pose, all_pairs=True))
        out.append(tightbvh.collide(tree_a, None, None, tree_b, None, pose))
        out.append(tightbvh.distance(tree_a, None, None, tree_b, None, pose))
        out.append(tightbvh.distance(tree_a, None, None, tree_b, None, pose, relative_error=0.1, upper_bound=0.5))
    return out


def assert_same_tree(tree, back):
    assert back is not tree
    nodes, back_nodes = tree.nodes(), back.nodes()
    assert nodes.keys() == back_nodes.keys()
    for key in nodes:
        assert same_bits(nodes[key], back_nodes[key]), key
    assert same_bits(tree.triangle_order, back.triangle_order)
    assert back.fitter == tree.fitter
    assert back.stats == tree.stats  # the build's stats and seconds travel too
    assert same_bits(back.mesh.vertices, tree.mesh.vertices) and same_bits(back.mesh.faces, tree.mesh.faces)


@pytest.mark.parametrize("how", COPIES)
def test_tree_round_trip_answers_every_query_the_same(built, how):
    tree_a, tree_b = built
    back_a, back_b = COPIES[how](tree_a), COPIES[how](tree_b)
    assert_same_tree(tree_a, back_a)
    assert_same_tree(tree_b, back_b)
    expected, got = answers(tree_a, tree_b), answers(back_a, back_b)
    assert any(r.hit for r in expected if isinstance(r, tightbvh.Result))
    assert any(d.distance > 0 for d in expected if isinstance(d, tightbvh.Distance))
    for e, g in zip(expected, got):
        assert_same(e, g)
    batch = tightbvh.collide_batch(tree_a, None, None, tree_b, None, np.stack(POSES), all_pairs=True, threads=1)
    back_batch = tightbvh.collide_batch(back_a, None, None, back_b, None, np.stack(POSES), all_pairs=True, threads=1)
    assert all(same_bits(x, y) for x, y in zip(batch, back_batch))


def test_tree_state_is_the_tree_file(built, tmp_path):
    tree = built[0]
    path = tmp_path / "elephant.tree"
    tree.save(path)
    state = tree.__getstate__()
    assert state[0] == path.read_bytes()  # the versioned tree format, byte for byte
    assert state[0][:8] == b"TBVHTREE" and int.from_bytes(state[0][8:12], "little") == 2


def test_a_tree_pickled_with_its_mesh_shares_it(built, elephant):
    tree = built[0]
    data = pickle.dumps((tree, elephant, tree))
    back_tree, back_mesh, again = pickle.loads(data)
    assert back_tree.mesh is back_mesh and again is back_tree  # one mesh, one tree: stored once
    assert len(data) < len(pickle.dumps(tree)) + len(pickle.dumps(elephant)) // 2
    shallow = copy.copy(tree)
    assert shallow.mesh is tree.mesh  # meshes are immutable: a shallow copy shares it
    assert copy.deepcopy(tree).mesh is not tree.mesh


def test_a_loaded_tree_without_a_mesh_travels(built, elephant, tmp_path):
    path = tmp_path / "a.tree"
    built[0].save(path)
    loaded = tightbvh.Tree.load(path)
    back = pickle.loads(pickle.dumps(loaded))
    assert back.mesh is None and back.fitter is None
    assert same_bits(back.nodes()["center"], loaded.nodes()["center"])
    assert back.stats == loaded.stats
    pose = POSES[0]
    assert_same(tightbvh.collide(back, elephant, None, back, elephant, pose, all_pairs=True),
                tightbvh.collide(loaded, elephant, None, loaded, elephant, pose, all_pairs=True))


def refit_tree(elephant):
    moved = tightbvh.Mesh(elephant.vertices * 1.5, elephant.faces)
    return tightbvh.refit(tightbvh.build(elephant, fitter="pca"), moved, fitter="approx")


def test_a_refitted_tree_travels(elephant):
    tree = refit_tree(elephant)
    back = pickle.loads(pickle.dumps(tree))
    assert_same_tree(tree, back)


def results(elephant, knot):
    """One of every result and container, with the interesting cases: hits and misses, beyond the
    upper bound, a solid inside another, failed validations, every fit method."""
    tree_a, tree_b = tightbvh.build(elephant, fitter="pca"), tightbvh.build(knot, fitter="pca")
    out = []
    for pose in POSES:
        out.append(tightbvh.collide(tree_a, None, None, tree_b, None, pose, all_pairs=True))
        out.append(tightbvh.distance(tree_a, None, None, tree_b, None, pose, upper_bound=0.5))
    vertices, faces = tetrahedron()
    big, small = tightbvh.Mesh(vertices * 10, faces), tightbvh.Mesh(vertices, faces)
    tree_big, tree_small = tightbvh.build(big), tightbvh.build(small)
    inside = pose_matrix(np.eye(3), [1, 1, 1])
    out.append(tightbvh.collide(tree_big, None, None, tree_small, None, inside, solid=True))
    out.append(tightbvh.distance(tree_big, None, None, tree_small, None, inside, solid=True))
    assert out[-1].inside == "b_in_a" and out[-2].inside == "b_in_a"
    out.append(tightbvh.distance(tree_big, None, None, tree_small, None, inside, signed_distance=True))
    assert out[-1].deepest == "b_in_a" and out[-1].distance < 0
    out.append(tree_a.validate())
    out.append(tree_a.validate(tightbvh.Mesh(elephant.vertices * 2, elephant.faces)))
    assert out[-2].ok and not out[-1].ok
    for method in tightbvh.fit_methods():
        out.append(tightbvh.fit(elephant.vertices[::10], method=method))
    return out


@pytest.mark.parametrize("how", COPIES)
def test_results_and_containers_compare_equal_field_by_field(elephant, knot, how):
    objects = results(elephant, knot)
    assert {type(o) for o in objects} == {tightbvh.Result, tightbvh.Distance, tightbvh.TreeCheck, tightbvh.Box,
                                          tightbvh.Ball, tightbvh.Ellipsoid, tightbvh.Dop}
    assert any(isinstance(o, tightbvh.Distance) and o.beyond_upper_bound for o in objects)
    for obj in objects:
        back = COPIES[how](obj)
        assert back is not obj
        assert_same(obj, back)


def test_every_class_of_the_module_pickles():
    classes = [c for c in vars(tightbvh).values() if isinstance(c, type)]
    assert len(classes) >= 9
    for cls in classes:  # their own, not object's default __getstate__
        assert "__getstate__" in vars(cls) and "__setstate__" in vars(cls), cls.__name__


class Forged:
    """Unpickles as `cls` with `state`: what a tampered or foreign pickle stream does."""

    def __init__(self, cls, state):
        self.cls, self.state = cls, state

    def __reduce__(self):
        return copyreg.__newobj__, (self.cls,), self.state


def unpickle_forged(cls, state):
    # Protocol 1 writes __newobj__ as a plain call (protocol 2 would check the class of Forged):
    # loading calls cls.__new__(cls), then __setstate__(state), as for any pickle of cls.
    return pickle.loads(pickle.dumps(Forged(cls, state), protocol=1))


def test_malformed_states_are_errors_not_crashes(elephant, knot):
    tree = tightbvh.build(elephant, fitter="pca")
    other = tightbvh.build(knot, fitter="pca")
    good = tree.__getstate__()
    data = good[0]
    flipped = data[:200] + bytes([data[200] ^ 0x10]) + data[201:]
    version = data[:8] + (7).to_bytes(4, "little") + data[12:]
    vertices, faces = tetrahedron()
    bad = {
        tightbvh.Tree: [
            (42, TypeError), ((), ValueError), (good[:3], ValueError), (good + (None,), ValueError),
            (("not bytes",) + good[1:], TypeError),
            ((b"",) + good[1:], ValueError), ((data[:100],) + good[1:], ValueError),
            ((data[:-1],) + good[1:], ValueError), ((data + b"\0",) + good[1:], ValueError),
            ((flipped,) + good[1:], ValueError), ((version,) + good[1:], ValueError),
            ((data, "a mesh", None, None), TypeError),
            ((other.__getstate__()[0], elephant, None, None), ValueError),  # another mesh's tree
            ((data, elephant, "no-such-fitter", None), ValueError), ((data, elephant, 3, None), TypeError),
            ((data, elephant, "pca", (1.0, 2)), ValueError), ((data, elephant, "pca", "stats"), TypeError),
        ],
        tightbvh.Mesh: [
            ([vertices, faces], TypeError), ((vertices,), ValueError), ((vertices, faces + 10), ValueError),
            ((vertices, faces.astype(float)), TypeError), ((vertices[:, :2], faces), ValueError),
            ((np.full_like(vertices, np.nan), faces), ValueError), ((vertices, faces[:0]), ValueError),
        ],
        tightbvh.Result: [
            ((True,), ValueError), ((1, np.zeros((0, 2), np.uint32), 0, 0, "none"), TypeError),
            ((True, [[1, 2]], 0, 0, "none"), TypeError),
            ((True, np.zeros((3, 3), np.uint32), 0, 0, "none"), ValueError),
            ((True, np.zeros((1, 2), np.int64), 0, 0, "none"), TypeError),
            ((True, np.zeros((1, 2), np.uint32), -1, 0, "none"), ValueError),
            ((True, np.zeros((1, 2), np.uint32), 0, 0, "sideways"), ValueError),
        ],
        tightbvh.Distance: [
            ((1.0,) * 10, TypeError), (("1", False, (0, 0)) + ((0.0,) * 3,) * 4 + (0, 0, "none"), TypeError),
            ((1.0, False, (0, -1)) + ((0.0,) * 3,) * 4 + (0, 0, "none"), ValueError),
            ((1.0, False, (0, 2**32)) + ((0.0,) * 3,) * 4 + (0, 0, "none"), ValueError),
            ((1.0, False, (0, 0)) + ((0.0,) * 2,) * 4 + (0, 0, "none"), ValueError),
        ],
        tightbvh.Box: [((0.0,) * 3, TypeError), (((0.0,) * 2, (0.0,) * 9, (0.0,) * 3), ValueError),
                       (((0.0,) * 3, (0.0,) * 8, (0.0,) * 3), ValueError),
                       (((0.0,) * 3, "axes", (0.0,) * 3), TypeError)],
        tightbvh.Ball: [(((0.0,) * 3, "1"), TypeError), (((0.0,) * 4, 1.0), ValueError)],
        tightbvh.Ellipsoid: [(((0.0,) * 3, (0.0,) * 9, [None] * 3), TypeError)],
        tightbvh.Dop: [(("dop99", (0.0,) * 13, (0.0,) * 13), ValueError),
                       (("dop14", (0.0,) * 7, (0.0,) * 13), ValueError)],
        tightbvh.TreeCheck: [((["x"],), TypeError), (((1,),), TypeError), ("errors", TypeError)],
    }
    for cls, cases in bad.items():
        for state, error in cases:
            with pytest.raises(error) as raised:
                unpickle_forged(cls, state)
            assert str(raised.value), (cls, state)  # the message says what is wrong
    assert unpickle_forged(tightbvh.Tree, good).node_count == tree.node_count  # the forger itself works
