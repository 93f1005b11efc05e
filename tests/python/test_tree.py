"""build(), Tree: stats and saved files equal to the CLI's (`tightbvh build --json`, `-o`), save/load,
validation, keeping the mesh alive, option and file errors."""
import gc
import threading
import time

import numpy as np
import pytest
import tightbvh
from conftest import MESHES, tetrahedron


def comparable(stats):
    return {k: v for k, v in stats.items() if k != "seconds"}


@pytest.mark.parametrize("fitter, split, leaf_size", [("auto", "rapid", 1), ("approx", "median", 4), ("pca", "binned", 2)])
def test_build_equals_the_cli_bit_for_bit(cli, tmp_path, elephant, fitter, split, leaf_size):
    cli_tree = tmp_path / "cli.tree"
    out = cli("build", MESHES / "elephant.off", "--fitter", fitter, "--split", split, "--leaf-size", leaf_size,
              "-o", cli_tree)
    tree = tightbvh.build(elephant, fitter=fitter, split=split, leaf_size=leaf_size)
    stats = tree.stats
    assert stats["seconds"] > 0
    expected = {k: out[k] for k in comparable(stats)}
    assert comparable(stats) == expected  # every number, doubles included, is the same
    assert tree.fitter == out["fitter"] == fitter
    py_tree = tmp_path / "py.tree"
    tree.save(py_tree)
    assert py_tree.read_bytes() == cli_tree.read_bytes()  # every box bit for bit


def test_build_defaults_are_the_libraries(elephant):
    tree = tightbvh.build(elephant)
    assert tree.fitter == "auto"
    explicit = tightbvh.build(elephant, fitter="auto", split="rapid", leaf_size=1, threads=1)
    assert_same_tree(tree, explicit)  # and the same for any thread count


def assert_same_tree(a, b):
    assert a.triangle_order.tolist() == b.triangle_order.tolist()
    for key, value in a.nodes().items():
        np.testing.assert_array_equal(value, b.nodes()[key])


def test_every_fitter_builds_a_valid_tree():
    rng = np.random.default_rng(3)
    vertices = rng.normal(size=(60, 3))
    faces = rng.integers(0, 60, size=(80, 3))
    mesh = tightbvh.Mesh(vertices, faces)
    assert tightbvh.fitter_names()[0] == "auto"
    for fitter in tightbvh.fitter_names():
        tree = tightbvh.build(mesh, fitter=fitter, leaf_size=2)
        check = tree.validate()
        assert check and check.ok and check.errors == [], fitter
        assert tree.triangle_count == 80
        nodes = tree.nodes()
        leaves = nodes["count"] > 0
        assert nodes["count"][leaves].sum() == 80 and tree.stats["leaves"] == leaves.sum()
        # every leaf box contains its triangles' corners
        for i in np.flatnonzero(leaves):
            triangles = tree.triangle_order[nodes["first"][i] : nodes["first"][i] + nodes["count"][i]]
            corners = vertices[faces[triangles].ravel()]
            local = (corners - nodes["center"][i]) @ nodes["axes"][i]
            assert (np.abs(local) <= nodes["half_extents"][i] + 1e-9).all()


def test_save_load_and_validate(tmp_path, elephant, knot):
    tree = tightbvh.build(elephant, fitter="pca")
    path = tmp_path / "elephant.tree"
    tree.save(str(path))
    loaded = tightbvh.Tree.load(path)
    assert loaded.mesh is None and loaded.fitter is None
    assert_same_tree(tree, loaded)
    assert comparable(loaded.stats) == comparable(tree.stats)
    assert loaded.validate()  # structure only
    assert loaded.validate(elephant)
    bad = loaded.validate(knot)
    assert not bad and "triangle" in bad.errors[0]
    with_mesh = tightbvh.Tree.load(path, mesh=elephant)
    assert with_mesh.mesh is elephant
    with pytest.raises(ValueError, match="elephant.tree: not a tree of this mesh"):
        tightbvh.Tree.load(path, mesh=knot)


def test_inspect_of_a_python_tree_equals_its_stats(cli, tmp_path, knot):
    tree = tightbvh.build(knot, fitter="approx", leaf_size=3)
    tree.save(tmp_path / "knot.tree")
    out = cli("inspect", tmp_path / "knot.tree", "--mesh", MESHES / "knot1.off")
    assert out["valid"] and out["sum_volume"] == tree.stats["sum_volume"] and out["nodes"] == tree.node_count


def test_a_tree_keeps_its_mesh_alive():
    v, f = tetrahedron()
    tree = tightbvh.build(tightbvh.Mesh(v, f))
    gc.collect()
    assert tree.mesh.face_count == 4
    np.testing.assert_array_equal(tree.mesh.vertices, v)
    assert tightbvh.collide(tree, None, None, tree, None, np.eye(4)).hit


def test_build_releases_the_gil():
    # An approx build over the elephant (5.6k triangles) takes a while; a Python thread must run meanwhile.
    mesh = tightbvh.load_mesh(MESHES / "elephant.off")
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    time.sleep(0.01)
    before = len(ticks)
    tightbvh.build(mesh, fitter="approx", threads=1)
    during = len(ticks) - before
    stop.set()
    counter.join()
    assert during > 5


def test_load_errors(tmp_path):
    with pytest.raises(ValueError, match="missing.tree"):
        tightbvh.Tree.load(tmp_path / "missing.tree")
    garbage = tmp_path / "garbage.tree"
    garbage.write_bytes(b"TBVHTREE" + bytes(40))
    with pytest.raises(ValueError, match="garbage.tree"):
        tightbvh.Tree.load(garbage)
    with pytest.raises(ValueError, match="dir"):
        tightbvh.build(tightbvh.Mesh(*tetrahedron())).save(tmp_path / "no" / "dir" / "x.tree")


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"fitter": "nope"}, ValueError, "fitter: unknown fitter 'nope'"),
        ({"split": "nope"}, ValueError, "split: unknown split 'nope'"),
        ({"leaf_size": 0}, ValueError, r"leaf_size: must be in \[1, "),
        ({"leaf_size": -3}, ValueError, r"leaf_size: must be in \[1, "),
        ({"leaf_size": 2.0}, TypeError, "leaf_size: expected an integer"),
        ({"threads": -1}, ValueError, r"threads: must be in \[0, 4096\], got -1"),
        ({"grid": 0}, ValueError, r"grid: must be in \[1, 64\]"),
        ({"grid": 2, "epsilon": 0.1}, ValueError, "grid and epsilon exclude each other"),
        ({"epsilon": 0.0}, ValueError, "epsilon: must be a positive finite number"),
        ({"epsilon": "x"}, TypeError, "epsilon: expected a number"),
    ],
)
def test_build_option_errors(kwargs, error, message):
    with pytest.raises(error, match=message):
        tightbvh.build(tightbvh.Mesh(*tetrahedron()), **kwargs)


def test_build_mesh_errors():
    with pytest.raises(TypeError, match="mesh: expected a tightbvh.Mesh or an object with .vertices and .faces"):
        tightbvh.build("meshes/elephant.off")


def test_a_tree_loaded_without_its_mesh_needs_one_for_queries(tmp_path):
    tree = tightbvh.build(tightbvh.Mesh(*tetrahedron()))
    tree.save(tmp_path / "t.tree")
    loaded = tightbvh.Tree.load(tmp_path / "t.tree")
    with pytest.raises(TypeError, match="mesh_a: None, and the tree has no mesh of its own"):
        tightbvh.collide(loaded, None, None, tree, None, None)
    assert tightbvh.collide(loaded, tree.mesh, None, tree, None, None).hit


def test_package_exports_and_reprs(elephant):
    for name in tightbvh.__all__:
        assert hasattr(tightbvh, name), name
    assert tightbvh.__version__.count(".") == 2
    tree = tightbvh.build(elephant, fitter="pca")
    assert repr(elephant) == "<tightbvh.Mesh: 2775 vertices, 5558 faces>"
    assert repr(tree) == f"<tightbvh.Tree: {tree.node_count} nodes, 5558 triangles>"
    assert repr(tree.validate()) == "<tightbvh.TreeCheck: valid>"
    assert repr(tightbvh.collide(tree, None, None, tree, None, None)).startswith("<tightbvh.Result hit=True")
    for method, kind in [("aabb", "Box"), ("ball", "Ball"), ("ellipsoid", "Ellipsoid"), ("dop18", "Dop")]:
        assert repr(tightbvh.fit(elephant, method)).startswith(f"<tightbvh.{kind} ")
