"""tightbvh.Model and tightbvh.Scene: every CollisionManager method against brute force over the
object pairs with tightbvh.collide / tightbvh.distance, shared models, errors, the trimesh
switch example, and trimesh itself when it is importable."""
import itertools
import math
import os
import pickle
import subprocess
import sys
import types

import numpy as np
import pytest

import tightbvh
from conftest import MESHES, SOURCE_DIR, pose_matrix, rotation, tetrahedron


def box(size=(1.0, 1.0, 1.0)):
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64) * size
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return types.SimpleNamespace(vertices=corners, faces=faces)


def tet():
    vertices, faces = tetrahedron()
    return types.SimpleNamespace(vertices=vertices, faces=faces)


def random_transform(rng, spread):
    return pose_matrix(rotation(rng.normal(size=3), rng.uniform(0, math.pi)), rng.uniform(-spread, spread, size=3))


class Reference:
    """Objects (name -> (mesh, tree, transform)) queried pair by pair with the pair queries."""

    def __init__(self):
        self.objects = {}
        self.trees = {}

    def tree(self, mesh):
        if id(mesh) not in self.trees:
            self.trees[id(mesh)] = (mesh, tightbvh.build(mesh))
        return self.trees[id(mesh)][1]

    def add(self, name, mesh, transform):
        self.objects[name] = (mesh, self.tree(mesh), transform)

    def collide(self, a, b, all_pairs=False):
        ma, ta, pa = a
        mb, tb, pb = b
        return tightbvh.collide(ta, ma, pa, tb, mb, pb, all_pairs=all_pairs)

    def distance(self, a, b):
        ma, ta, pa = a
        mb, tb, pb = b
        return tightbvh.distance(ta, ma, pa, tb, mb, pb).distance

    def query(self, mesh, transform):
        return (mesh, self.tree(mesh), transform)


def random_scene(seed, count=12, spread=1.6):
    """Boxes and tetrahedra (two shared mesh objects, one box of its own) at random poses."""
    rng = np.random.default_rng(seed)
    meshes = [box(), tet(), box((0.4, 1.5, 0.3))]
    scene, reference = tightbvh.Scene(), Reference()
    for i in range(count):
        mesh = meshes[i % 3]
        transform = random_transform(rng, spread)
        scene.add_object(f"obj{i:02d}", mesh, transform)
        reference.add(f"obj{i:02d}", mesh, transform)
    return scene, reference, rng


def touching_pairs(reference, allowed=()):
    objects = reference.objects
    return {(a, b) for a, b in itertools.combinations(sorted(objects), 2)
            if (a, b) not in allowed and reference.collide(objects[a], objects[b]).hit}


@pytest.mark.parametrize("seed", range(4))
def test_in_collision_internal_equals_brute_force(seed):
    scene, reference, _ = random_scene(seed)
    expected = touching_pairs(reference)
    assert expected, "the random scene should have touching pairs"
    assert scene.in_collision_internal() is True
    hit, names = scene.in_collision_internal(return_names=True)
    assert hit is True and names == expected
    # Allowed pairs are never reported.
    allowed = sorted(expected)[:2]
    for a, b in allowed:
        scene.allow(b, a)
    assert scene.in_collision_internal(return_names=True)[1] == expected - set(allowed)
    assert scene.allowed(*allowed[0]) and scene.allowed(allowed[0][1], allowed[0][0])
    scene.disallow(*allowed[0])
    assert not scene.allowed(*allowed[0])
    assert scene.in_collision_internal(return_names=True)[1] == expected - set(allowed[1:])


@pytest.mark.parametrize("seed", range(3))
def test_in_collision_single_equals_brute_force(seed):
    scene, reference, rng = random_scene(seed)
    probe = box((1.2, 1.2, 1.2))
    sizes = set()
    for _ in range(16):
        transform = random_transform(rng, 2.2)
        query = reference.query(probe, transform)
        expected = {n for n, o in reference.objects.items() if reference.collide(o, query).hit}
        assert scene.in_collision_single(probe, transform) is bool(expected)
        assert scene.in_collision_single(probe, transform, return_names=True) == (bool(expected), expected)
        sizes.add(min(len(expected), 2))
    assert sizes == {0, 1, 2}, "the probe should miss, touch one object and touch several"


def test_in_collision_other_equals_brute_force():
    robot, robot_ref, rng = random_scene(1, count=6)
    world, world_ref, _ = random_scene(2, count=8)
    expected = {(a, b) for a, oa in robot_ref.objects.items() for b, ob in world_ref.objects.items()
                if robot_ref.collide(oa, ob).hit}
    assert expected
    assert robot.in_collision_other(world) is True
    assert robot.in_collision_other(world, return_names=True) == (True, expected)
    assert world.in_collision_other(robot, return_names=True)[1] == {(b, a) for a, b in expected}


def test_min_distance_internal_equals_brute_force():
    scene, reference, _ = random_scene(5, count=8, spread=4.0)
    objects = reference.objects
    distances = {(a, b): reference.distance(objects[a], objects[b])
                 for a, b in itertools.combinations(sorted(objects), 2)}
    least = min(distances.values())
    d, names, data = scene.min_distance_internal(return_names=True, return_data=True)
    assert d == pytest.approx(least, rel=1e-12, abs=1e-12)
    assert distances[names] == pytest.approx(least, rel=1e-12, abs=1e-12)
    assert scene.min_distance_internal() == d
    assert data.names == set(names) and data.distance == d
    assert np.linalg.norm(data.point(names[0]) - data.point(names[1])) == pytest.approx(d, abs=1e-9)


def test_min_distance_single_and_other_equal_brute_force():
    scene, reference, rng = random_scene(6, count=8, spread=4.0)
    probe = tet()
    for _ in range(4):
        transform = random_transform(rng, 5.0)
        query = reference.query(probe, transform)
        distances = {n: reference.distance(o, query) for n, o in reference.objects.items()}
        d, name = scene.min_distance_single(probe, transform, return_name=True)
        assert d == pytest.approx(min(distances.values()), rel=1e-12, abs=1e-12)
        assert distances[name] == pytest.approx(d, rel=1e-12, abs=1e-12)
        d2, data = scene.min_distance_single(probe, transform, return_data=True)
        assert d2 == d and data.names == {name, "__external"}
    other, other_ref, _ = random_scene(7, count=5, spread=4.0)
    for o in other.names:
        other.set_transform(o, other.transform(o) @ pose_matrix(np.eye(3), [9.0, 0.0, 0.0]))
        mesh, tree, transform = other_ref.objects[o]
        other_ref.objects[o] = (mesh, tree, other.transform(o))
    distances = {(a, b): reference.distance(oa, ob) for a, oa in reference.objects.items()
                 for b, ob in other_ref.objects.items()}
    d, names = scene.min_distance_other(other, return_names=True)
    assert d > 0 and d == pytest.approx(min(distances.values()), rel=1e-12)
    assert distances[names] == pytest.approx(d, rel=1e-12)


def test_return_data_lists_every_touching_triangle_pair():
    scene, reference, _ = random_scene(3)
    hit, names, contacts = scene.in_collision_internal(return_names=True, return_data=True)
    expected = set()
    for a, b in names:
        pairs = reference.collide(reference.objects[a], reference.objects[b], all_pairs=True).pairs
        expected |= {(a, b, int(i), int(j)) for i, j in pairs}
    got = set()
    for c in contacts:
        a, b = sorted(c.names)
        got.add((a, b, c.index(a), c.index(b)))
        assert c.point.shape == (3,) and np.all(np.isfinite(c.point))
    assert got == expected
    assert hit is True and scene.in_collision_internal(return_data=True)[0] is True
    hit, data = scene.in_collision_single(box(), np.eye(4), return_data=True)
    assert all("__external" in c.names for c in data) and len(data) > 0 and hit


def test_return_shapes_match_collision_manager():
    scene = tightbvh.Scene()
    assert scene.in_collision_internal() is False
    assert scene.in_collision_internal(return_names=True) == (False, set())
    assert scene.in_collision_internal(return_data=True) == (False, [])
    assert scene.in_collision_internal(True, True) == (False, set(), [])
    assert scene.min_distance_internal() == math.inf
    assert scene.min_distance_internal(return_names=True) == (math.inf, None)
    scene.add_object("a", box())
    scene.add_object("b", box(), pose_matrix(np.eye(3), [3.0, 0, 0]))
    d = scene.min_distance_internal()
    assert isinstance(d, float) and d == pytest.approx(2.0)
    assert scene.min_distance_internal(return_names=True) == (d, ("a", "b"))
    assert scene.min_distance_single(tet(), return_name=True) == (0.0, "a")
    assert len(scene.min_distance_single(tet(), return_name=True, return_data=True)) == 3
    other = tightbvh.Scene()
    other.add_object("z", tet(), pose_matrix(np.eye(3), [3.2, 0.2, 0.2]))
    assert other.in_collision_other(scene, return_names=True) == (True, {("z", "b")})
    assert other.min_distance_other(scene, return_names=True) == (0.0, ("z", "b"))


def test_same_mesh_object_shares_one_model():
    cube, other_cube = box(), box()
    scene = tightbvh.Scene()
    scene.add_object("a", cube)
    scene.add_object("b", cube, pose_matrix(np.eye(3), [5.0, 0, 0]))
    assert scene.model_count == 1 and scene.model("a") == scene.model("b")
    scene.add_object("c", other_cube)  # equal arrays, another object: its own model
    assert scene.model_count == 2 and scene.model("c") != scene.model("a")
    bytes_two = scene.model_bytes
    model = tightbvh.Model(tet())
    scene.add_object("d", model)
    scene.add_object("e", model)
    assert scene.model("d") == model and scene.model("e") == model and scene.model_count == 3
    assert scene.model_bytes == bytes_two + model.bytes
    # Replacing an object by its own mesh keeps the model; removing every user drops it.
    shared = scene.model("a")
    scene.add_object("a", cube, pose_matrix(np.eye(3), [0, 5.0, 0]))
    assert scene.model("a") == shared == scene.model("b")
    scene.remove_object("a")
    scene.remove_object("b")
    assert scene.model_count == 2 and scene.names == ["c", "d", "e"]
    scene.add_object("f", cube)
    assert scene.model("f") != shared


def test_model_from_mesh_and_path():
    knot = tightbvh.Model(MESHES / "knot1.off", fitter="approx")
    mesh = tightbvh.load_mesh(MESHES / "knot1.off")
    assert knot.triangle_count == mesh.face_count == knot.mesh.face_count
    assert np.array_equal(knot.mesh.vertices, mesh.vertices)
    assert knot.tree.triangle_count == knot.triangle_count and knot.tree.node_count == knot.node_count
    assert knot.tree.validate() and knot.fitter == "approx"
    assert knot.bytes > mesh.face_count * 12
    assert tightbvh.Model(str(MESHES / "knot1.off")).triangle_count == knot.triangle_count
    with pytest.raises(ValueError, match="fitter"):
        tightbvh.Model(mesh, fitter="nope")
    with pytest.raises(ValueError):
        tightbvh.Model(MESHES / "no_such_mesh.off")
    with pytest.raises(TypeError, match="mesh_or_path"):
        tightbvh.Model(42)


def test_shipped_meshes_scene_equals_brute_force(elephant, knot):
    rng = np.random.default_rng(11)
    scene, reference = tightbvh.Scene(threads=2), Reference()
    for i, mesh in enumerate([elephant, knot, elephant, knot, elephant]):
        transform = random_transform(rng, 0.6)
        scene.add_object(f"m{i}", mesh, transform)
        reference.add(f"m{i}", mesh, transform)
    assert scene.model_count == 2
    expected = touching_pairs(reference)
    assert expected and len(expected) < 10
    assert scene.in_collision_internal(return_names=True)[1] == expected
    objects = reference.objects
    least = min(reference.distance(objects[a], objects[b]) for a, b in itertools.combinations(objects, 2))
    assert scene.min_distance_internal() == pytest.approx(least, abs=1e-12)


def test_set_transforms_equals_set_transform_and_batch_equals_single():
    scene, _, rng = random_scene(8)
    twin, _, _ = random_scene(8)
    names = scene.names[::2]
    transforms = np.stack([random_transform(rng, 1.6) for _ in names])
    scene.set_transforms(names, transforms)
    for name, transform in zip(names, transforms):
        twin.set_transform(name, transform)
    assert scene.in_collision_internal(return_names=True) == twin.in_collision_internal(return_names=True)
    assert all(np.array_equal(scene.transform(n), t) for n, t in zip(names, transforms))
    probe = tet()
    poses = np.stack([random_transform(rng, 1.6) for _ in range(10)])
    batch = scene.in_collision_batch(probe, poses)
    assert batch == [scene.in_collision_single(probe, p, return_names=True)[1] for p in poses]


def test_add_object_replaces_an_object_of_the_same_name():
    scene = tightbvh.Scene()
    scene.add_object("a", box())
    scene.add_object("b", box(), pose_matrix(np.eye(3), [0.5, 0, 0]))
    assert scene.in_collision_internal() is True
    scene.add_object("b", tet(), pose_matrix(np.eye(3), [4.0, 0, 0]))  # as trimesh: replaced
    assert len(scene) == 2 and scene.in_collision_internal() is False


def test_errors_name_what_is_wrong():
    scene = tightbvh.Scene()
    scene.add_object("a", box())
    with pytest.raises(ValueError, match="remove_object: 'x' not in the scene"):
        scene.remove_object("x")
    with pytest.raises(ValueError, match="set_transform: 'x' not in the scene"):
        scene.set_transform("x", np.eye(4))
    with pytest.raises(ValueError, match="allow: 'x'"):
        scene.allow("a", "x")
    with pytest.raises(TypeError, match="name: expected a str"):
        scene.add_object(3, box())
    with pytest.raises(TypeError, match="mesh"):
        scene.add_object("b", object())
    with pytest.raises(ValueError, match="transform"):
        scene.add_object("b", box(), np.eye(3))
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(ValueError, match="transform"):
        scene.set_transform("a", bad)
    bad = np.eye(4)
    bad[1, 3] = np.nan
    with pytest.raises(ValueError, match="transform"):
        scene.in_collision_single(box(), bad)
    with pytest.raises(ValueError, match="2 names but 1 transforms"):
        scene.set_transforms(["a", "a"], np.eye(4)[None])
    with pytest.raises(ValueError, match="other_manager"):
        scene.in_collision_other(scene)
    # A failed call changes nothing.
    assert scene.names == ["a"] and np.array_equal(scene.transform("a"), np.eye(4))


def filters_meet(scenes, a, b):
    """C++ Scene::tested for two objects of `scene` (or of two scenes): each one's group meets the other's mask."""
    (group_a, mask_a), (group_b, mask_b) = scenes[0].filter(a), scenes[1].filter(b)
    return bool(group_a & mask_b) and bool(group_b & mask_a)


def filtered_scene(seed, count=16, spread=1.6):
    """random_scene with random filter bits (3 groups), some set by add_object, some by set_filter."""
    scene, reference, rng = random_scene(seed, count, spread)
    for i, name in enumerate(scene.names):
        group, mask = 1 << int(rng.integers(0, 2)), int(rng.choice([1, 2, 3, 3]))
        if i % 2:
            mesh, _, transform = reference.objects[name]
            scene.add_object(name, mesh, transform, group=group, mask=mask)  # replaced: keeps its name
        else:
            scene.set_filter(name, group, mask)
    return scene, reference, rng


@pytest.mark.parametrize("seed", range(3))
def test_filters_equal_brute_force(seed):
    scene, reference, rng = filtered_scene(seed)
    objects = reference.objects
    every = touching_pairs(reference)
    expected = {(a, b) for a, b in every if filters_meet((scene, scene), a, b)}
    assert expected and expected != every, "the filters should keep some touching pairs and drop others"
    assert scene.in_collision_internal(return_names=True) == (True, expected)
    distances = {(a, b): reference.distance(objects[a], objects[b])
                 for a, b in itertools.combinations(sorted(objects), 2) if filters_meet((scene, scene), a, b)}
    d, names = scene.min_distance_internal(return_names=True)
    assert d == pytest.approx(min(distances.values()), abs=1e-12) and names in distances
    # Filters survive pickling.
    clone = pickle.loads(pickle.dumps(scene))
    assert [clone.filter(n) for n in clone.names] == [scene.filter(n) for n in scene.names]
    assert clone.in_collision_internal(return_names=True)[1] == expected
    # Every bit set again: every touching pair is back.
    for name in scene.names:
        scene.set_filter(name, 0xFFFFFFFF, 0xFFFFFFFF)
    assert scene.in_collision_internal(return_names=True)[1] == every
    # The query mesh of in_collision_single ignores the filters, even of objects meeting nothing.
    for name in scene.names:
        scene.set_filter(name, 1, 0)
    assert scene.in_collision_internal() is False
    probe = box((1.2, 1.2, 1.2))
    transform = random_transform(rng, 1.0)
    query = reference.query(probe, transform)
    assert scene.in_collision_single(probe, transform, return_names=True)[1] == {
        n for n, o in objects.items() if reference.collide(o, query).hit}


def test_filters_must_meet_both_ways():
    scene = tightbvh.Scene()
    scene.add_object("a", box(), group=1, mask=2)
    scene.add_object("b", box(), pose_matrix(np.eye(3), [0.5, 0, 0]), group=2, mask=1)
    assert scene.in_collision_internal() is True and scene.filter("b") == (2, 1)
    scene.set_filter("b", 2, 2)  # b's group meets a's mask, a's group no longer meets b's mask
    assert scene.in_collision_internal() is False and scene.distance_within_internal(1.0) == {}
    assert scene.min_distance_internal() == math.inf
    scene.set_filter("b", 3, 1)
    assert scene.in_collision_internal() is True


def test_filters_apply_across_scenes():
    robot, robot_ref, _ = filtered_scene(1, count=6)
    world, world_ref, _ = filtered_scene(2, count=8)
    every = {(a, b) for a, oa in robot_ref.objects.items() for b, ob in world_ref.objects.items()
             if robot_ref.collide(oa, ob).hit}
    expected = {(a, b) for a, b in every if filters_meet((robot, world), a, b)}
    assert expected and expected != every
    assert robot.in_collision_other(world, return_names=True) == (True, expected)
    within = robot.distance_within_other(world, 0.3)
    assert set(within) == {(a, b) for a, oa in robot_ref.objects.items() for b, ob in world_ref.objects.items()
                           if filters_meet((robot, world), a, b) and robot_ref.distance(oa, ob) < 0.3}


def within_brute_force(reference, max_distance, scenes=None):
    objects = reference.objects
    found = {}
    for a, b in itertools.combinations(sorted(objects), 2):
        if scenes is None or filters_meet(scenes, a, b):
            d = reference.distance(objects[a], objects[b])
            if d < max_distance:
                found[(a, b)] = d
    return found


def assert_same_distances(got, expected):
    assert set(got) == set(expected)
    for key, d in expected.items():
        assert got[key] == pytest.approx(d, rel=1e-12, abs=1e-12), key


@pytest.mark.parametrize("seed", range(3))
def test_distance_within_internal_equals_brute_force(seed):
    scene, reference, _ = random_scene(seed, count=10, spread=2.5)
    # Thresholds halfway between consecutive pair distances: each picks one more pair.
    every = sorted(set(within_brute_force(reference, math.inf).values()))
    thresholds = [(x + y) / 2 for x, y in zip(every, every[1:])][::7]
    sizes = set()
    for max_distance in thresholds:
        expected = within_brute_force(reference, max_distance)
        got = scene.distance_within_internal(max_distance)
        assert_same_distances(got, expected)
        sizes.add(len(expected))
        # In object order (the names were added in sorted order).
        assert list(got) == sorted(got)
    assert len(sizes) == len(thresholds) > 3, "each threshold should pick a different pair set"
    # Touching pairs are at 0, and equal in_collision_internal's pairs.
    touching = {k for k, d in scene.distance_within_internal(0.05).items() if d == 0.0}
    assert touching == scene.in_collision_internal(return_names=True)[1]
    distances, data = scene.distance_within_internal(0.5, return_data=True)
    assert distances.keys() == data.keys()
    for (a, b), d in data.items():
        assert d.names == {a, b} and d.distance == distances[(a, b)]
        assert np.linalg.norm(d.point(a) - d.point(b)) == pytest.approx(d.distance, abs=1e-9)
    # Allowed pairs and filters are not reported.
    allowed = next(iter(distances))
    scene.allow(*allowed)
    assert set(scene.distance_within_internal(0.5)) == set(distances) - {allowed}
    scene, reference, _ = filtered_scene(seed, count=10, spread=2.5)
    assert_same_distances(scene.distance_within_internal(0.5), within_brute_force(reference, 0.5, (scene, scene)))


def test_distance_within_single_and_other_equal_brute_force():
    scene, reference, rng = random_scene(6, count=8, spread=2.0)
    probe = tet()
    sizes = set()
    for _ in range(12):
        transform = random_transform(rng, 2.0)
        query = reference.query(probe, transform)
        expected = {n: d for n, o in reference.objects.items() if (d := reference.distance(o, query)) < 0.6}
        got = scene.distance_within_single(probe, 0.6, transform)
        assert_same_distances(got, expected)
        sizes.add(min(len(expected), 2))
        got, data = scene.distance_within_single(probe, 0.6, transform=transform, return_data=True)
        assert all(d.names == {n, "__external"} and d.distance == got[n] for n, d in data.items())
    assert sizes == {0, 1, 2}
    other, other_ref, _ = random_scene(7, count=5, spread=2.5)
    expected = {(a, b): d for a, oa in reference.objects.items() for b, ob in other_ref.objects.items()
                if (d := reference.distance(oa, ob)) < 0.4}
    assert expected
    assert_same_distances(scene.distance_within_other(other, 0.4), expected)
    assert set(other.distance_within_other(scene, 0.4)) == {(b, a) for a, b in expected}
    distances, data = scene.distance_within_other(other, 0.4, return_data=True)
    assert all(data[k].distance == distances[k] for k in distances)
    assert tightbvh.Scene().distance_within_internal(1.0) == {}


def test_filter_and_distance_within_errors():
    scene = tightbvh.Scene()
    scene.add_object("a", box())
    with pytest.raises(ValueError, match="add_object: group: must be in"):
        scene.add_object("b", box(), group=-1)
    with pytest.raises(ValueError, match="add_object: mask: must be in"):
        scene.add_object("b", box(), mask=1 << 32)
    with pytest.raises(TypeError, match="set_filter: group: expected an int"):
        scene.set_filter("a", 1.0, 1)
    with pytest.raises(ValueError, match="set_filter: 'x' not in the scene"):
        scene.set_filter("x", 1, 1)
    with pytest.raises(ValueError, match="max_distance must be > 0"):
        scene.distance_within_internal(0.0)
    with pytest.raises(ValueError, match="max_distance must be > 0"):
        scene.distance_within_single(box(), float("nan"))
    with pytest.raises(ValueError, match="other_manager"):
        scene.distance_within_other(scene, 1.0)
    assert scene.names == ["a"] and scene.filter("a") == (1, 0xFFFFFFFF)


def test_filters_and_clearance_example():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    script = SOURCE_DIR / "examples" / "python" / "scene_filters_and_clearance.py"
    out = subprocess.run([sys.executable, script], check=True, capture_output=True, text=True, env=env).stdout
    assert out.splitlines() == [
        "touching: False",
        "closer than 0.15: link0-table 0.020, link1-shelf 0.100, link1-table 0.020",
        "with the wall: link0-table 0.020, link1-shelf 0.100, link1-table 0.020, shelf-wall 0.050",
        "4 pairs within 0.15; pair queries agree"]


def test_trimesh_switch_example():
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    script = SOURCE_DIR / "examples" / "python" / "scene_trimesh_switch.py"
    out = subprocess.run([sys.executable, script], check=True, capture_output=True, text=True, env=env).stdout
    lines = out.splitlines()
    assert lines[0] == "touching: True [('left', 'middle')]"
    assert lines[1] == "probe: 1.500 from left"
    assert lines[2] == "after the move: [('left', 'middle'), ('middle', 'right')]"
    assert lines[3] == "1 model for 3 objects; pair queries agree"


def test_same_answers_as_trimesh_collision_manager():
    trimesh = pytest.importorskip("trimesh", reason="trimesh is not installed")
    try:
        manager = trimesh.collision.CollisionManager()
    except ValueError:
        pytest.skip("trimesh is installed without python-fcl")
    scene = tightbvh.Scene()
    rng = np.random.default_rng(4)
    meshes = [trimesh.creation.box(), trimesh.creation.icosphere(subdivisions=1)]
    for i in range(10):
        transform = random_transform(rng, 1.5)
        manager.add_object(f"o{i}", meshes[i % 2], transform)
        scene.add_object(f"o{i}", meshes[i % 2], transform)
    assert scene.in_collision_internal(return_names=True) == manager.in_collision_internal(return_names=True)
    probe = random_transform(rng, 1.5)
    assert (scene.in_collision_single(meshes[0], probe, return_names=True)
            == manager.in_collision_single(meshes[0], probe, return_names=True))


def test_solid_scene_reports_an_object_inside_another():
    small = pose_matrix(np.eye(3), [0.4, 0.4, 0.4])
    surfaces, solids = tightbvh.Scene(), tightbvh.Scene(solid=True)
    for scene in (surfaces, solids):
        scene.add_object("big", box())
        scene.add_object("small", box((0.2, 0.2, 0.2)), small)
    assert surfaces.in_collision_internal() is False and surfaces.min_distance_internal() > 0.3
    assert solids.in_collision_internal(return_names=True) == (True, {("big", "small")})
    assert solids.min_distance_internal() == 0.0
    data = solids.min_distance_internal(return_data=True)[1]  # a containment: no triangle pair
    assert data.distance == 0.0 and data.index("big") is None and data.index("small") is None
    assert pickle.loads(pickle.dumps(data)).index("small") is None
    assert surfaces.min_distance_internal(return_data=True)[1].index("small") is not None
    inner = pose_matrix(np.eye(3), [0.1, 0.1, 0.1])  # inside "big", away from "small"
    assert solids.in_collision_single(box((0.1, 0.1, 0.1)), inner, return_names=True) == (True, {"big"})
    assert surfaces.in_collision_single(box((0.1, 0.1, 0.1)), inner) is False
    open_scene = tightbvh.Scene(solid=True)
    open_scene.add_object("a", types.SimpleNamespace(vertices=np.eye(3), faces=np.array([[0, 1, 2]])))
    open_scene.add_object("b", box())
    with pytest.raises(ValueError):
        open_scene.in_collision_internal()


def test_scene_model_and_data_pickle_and_copy():
    import copy

    scene, _, _ = random_scene(9)
    names = scene.in_collision_internal(return_names=True)[1]
    a, b = sorted(names)[0]
    scene.allow(a, b)
    for clone in (pickle.loads(pickle.dumps(scene)), copy.deepcopy(scene), copy.copy(scene)):
        assert clone.names == scene.names and clone.model_count == scene.model_count == 3
        assert clone.allowed(a, b) and clone.threads == scene.threads and clone.solid == scene.solid
        assert clone.in_collision_internal(return_names=True, return_data=True)[1] == names - {(a, b)}
        assert clone.min_distance_internal(return_names=True) == scene.min_distance_internal(return_names=True)
        assert all(np.array_equal(clone.transform(n), scene.transform(n)) for n in scene.names)
    model = tightbvh.Model(tet(), fitter="pca")
    back = pickle.loads(pickle.dumps(model))
    assert back.fitter == "pca" and np.array_equal(back.mesh.vertices, model.mesh.vertices)
    assert back.tree.nodes()["half_extents"].tolist() == model.tree.nodes()["half_extents"].tolist()
    _, _, contacts = scene.in_collision_internal(return_names=True, return_data=True)
    contact = pickle.loads(pickle.dumps(contacts[0]))
    assert contact.names == contacts[0].names and contact.point.tolist() == contacts[0].point.tolist()
    assert contact.triangles == contacts[0].triangles
    _, data = scene.min_distance_single(tet(), pose_matrix(np.eye(3), [9.0, 0, 0]), return_data=True)
    back = pickle.loads(pickle.dumps(data))
    assert back.names == data.names and back.distance == data.distance and back.index("__external") == data.index(
        "__external")


def test_malformed_scene_states_are_errors():
    model = tightbvh.Model(tet())
    good = (1, False, (("a", model, np.eye(4)),), ())
    scene = tightbvh.Scene.__new__(tightbvh.Scene)
    scene.__setstate__(good)
    assert scene.names == ["a"] and scene.filter("a") == (1, 0xFFFFFFFF)  # 3 fields: the default filter bits
    scene = tightbvh.Scene.__new__(tightbvh.Scene)
    scene.__setstate__((1, False, (("a", model, np.eye(4), 4, 6),), ()))
    assert scene.filter("a") == (4, 6)
    bad_pose = np.eye(4)
    bad_pose[0, 0] = 3.0
    cases = [
        ((1, False, (("a", model, np.eye(4)), ("a", model, np.eye(4))), ()), ValueError, "duplicate name 'a'"),
        ((1, False, (("a", "model", np.eye(4)),), ()), TypeError, "must be a Model"),
        ((1, False, (("a", model, bad_pose),), ()), ValueError, "transform"),
        ((1, False, (("a", model, np.eye(4)),), (("a", "x"),)), ValueError, "'x' not in the scene"),
        ((1, False, ()), ValueError, "expected 4 fields"),
        ((1, False, (("a", model, np.eye(4), -1, 1),), ()), ValueError, "'a': group"),
        ((1, False, (("a", model, np.eye(4), 1, "all"),), ()), TypeError, "'a': mask"),
    ]
    for state, error, message in cases:
        with pytest.raises(error, match=message):
            tightbvh.Scene.__new__(tightbvh.Scene).__setstate__(state)
    with pytest.raises(ValueError):
        tightbvh.Model.__new__(tightbvh.Model).__setstate__((model.mesh, b"not a tree", None))
    with pytest.raises(ValueError, match="not a tree of this mesh|tree"):
        tightbvh.Model.__new__(tightbvh.Model).__setstate__(
            (tightbvh.as_mesh(box()), model.__getstate__()[1], None))
