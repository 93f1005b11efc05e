"""tightbvh.shapes against meshes: collide_shape and distance_shape, checked against the point
queries (a sphere is a point grown by its radius) and against geometry known in closed form."""
import numpy as np
import pytest
import tightbvh
from conftest import pose_matrix, rotation
from tightbvh.shapes import Box, Capsule, Sphere


@pytest.fixture(scope="module")
def elephant_model(elephant):
    return tightbvh.Model(elephant)


@pytest.fixture(scope="module")
def unit_cube():
    """The cube [-1, 1]^3, outward triangles."""
    corners = np.array([[1.0 if i & 1 else -1.0, 1.0 if i & 2 else -1.0, 1.0 if i & 4 else -1.0] for i in range(8)])
    faces = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return tightbvh.Mesh(corners, faces)


def translation(x, y, z):
    return pose_matrix(np.eye(3), [x, y, z])


def test_sphere_is_a_point_grown_by_its_radius(elephant, elephant_model):
    # distance(sphere) = max(0, distance(center) - r), and it touches exactly when that is 0.
    rng = np.random.default_rng(3)
    lo, hi = elephant.vertices.min(axis=0), elephant.vertices.max(axis=0)
    centers = lo - 0.2 + rng.random((40, 3)) * (hi - lo + 0.4)
    _, point_distances, _ = elephant_model.closest_points(centers)
    hits = 0
    for c, d in zip(centers, point_distances):
        r = 0.05
        got = tightbvh.distance_shape(Sphere(r), translation(*c), elephant_model)
        assert got.distance == pytest.approx(max(0.0, d - r), rel=1e-12, abs=1e-15)
        hit = tightbvh.collide_shape(Sphere(r), translation(*c), elephant_model)
        assert hit.hit == (d <= r) == got.intersecting
        hits += hit.hit
        if not got.intersecting:
            assert np.linalg.norm(got.point_shape - c) == pytest.approx(r, rel=1e-12)
            assert np.linalg.norm(got.point_mesh - c) == pytest.approx(d, rel=1e-12)
    assert 0 < hits < len(centers)


def test_closed_forms_against_a_unit_cube(unit_cube):
    model = tightbvh.Model(unit_cube)  # [-1, 1]^3
    assert tightbvh.distance_shape(Sphere(1.0), translation(3, 0, 0), model).distance == pytest.approx(1.0)
    capsule = tightbvh.distance_shape(Capsule(0.5, 4.0), translation(0, 3, 0), model)  # axis along z, at y = 3
    assert capsule.distance == pytest.approx(1.5) and capsule.point_mesh[1] == pytest.approx(1.0)
    box = tightbvh.distance_shape(Box(1, 1, 1), translation(0, 0, 2.5), model)
    assert box.distance == pytest.approx(1.0) and not box.beyond_upper_bound
    # Turned by 45 degrees about z, the box's vertical edge faces the cube, sqrt(0.5) from its center.
    turned = pose_matrix(rotation([0, 0, 1], np.pi / 4), [2.5, 0, 0])
    assert tightbvh.distance_shape(Box(1, 1, 1), turned, model).distance == pytest.approx(1.5 - np.sqrt(0.5))
    # A margin just above the gap reports the facing triangles, just below none.
    near = tightbvh.collide_shape(Sphere(1.0), translation(3, 0, 0), model, all_pairs=True, margin=1.0 + 1e-9)
    assert near.hit and len(near.triangles) > 0
    assert not tightbvh.collide_shape(Sphere(1.0), translation(3, 0, 0), model, margin=1.0 - 1e-9).hit
    far = tightbvh.distance_shape(Sphere(1.0), translation(30, 0, 0), model, upper_bound=5.0)
    assert far.beyond_upper_bound and far.triangle is None and far.point_mesh is None


def test_every_triangle_touches_the_fitted_box_around_it(elephant, elephant_model):
    # A fitted box contains the mesh; the shape is solid, so every triangle touches it.
    fitted = tightbvh.fit(elephant.vertices, method="pca")
    result = tightbvh.collide_shape(fitted, None, elephant_model, all_pairs=True)
    assert result.hit
    assert result.triangles.tolist() == list(range(len(elephant.faces)))
    assert result.triangles.dtype == np.int64
    # Moved away by twice its size, it touches nothing.
    away = translation(*(4 * fitted.half_extents.max() * np.ones(3)))
    assert not tightbvh.collide_shape(fitted, away, elephant_model).hit


def test_all_pairs_reports_touching_triangles_only(elephant, elephant_model):
    pose = translation(*elephant.vertices[100])
    result = tightbvh.collide_shape(Capsule(0.03, 0.2), pose, elephant_model, all_pairs=True)
    assert result.hit and result.stats["triangle_tests"] >= len(result.triangles) > 0
    assert np.all(np.diff(result.triangles) > 0)  # sorted, unique
    first = tightbvh.collide_shape(Capsule(0.03, 0.2), pose, elephant_model)
    assert first.hit and len(first.triangles) == 1 and first.triangles[0] in result.triangles


def test_shapes_and_bad_input(elephant_model):
    assert Box([1, 2, 3]).extents.tolist() == [1, 2, 3] == Box(1, 2, 3).extents.tolist()
    assert (Sphere(2).radius, Capsule(1, 3).length) == (2, 3)
    assert "Capsule" in repr(Capsule(1, 3))
    with pytest.raises(ValueError, match="radius"):
        Sphere(-1.0)
    with pytest.raises(ValueError, match="length"):
        Capsule(1.0, float("nan"))
    with pytest.raises(ValueError, match="extents"):
        Box([1, 2])
    with pytest.raises(TypeError, match="shape must be"):
        tightbvh.collide_shape("ball", None, elephant_model)
    with pytest.raises(ValueError):
        tightbvh.collide_shape(Sphere(1), np.full((4, 4), np.nan), elephant_model)
    with pytest.raises(ValueError, match="margin"):
        tightbvh.collide_shape(Sphere(1), None, elephant_model, margin=-1.0)


def test_shapes_in_a_scene(elephant, elephant_model):
    import pickle

    scene = tightbvh.Scene()
    scene.add_object("elephant", elephant_model)
    top = elephant.vertices[np.argmax(elephant.vertices[:, 2])]
    scene.add_object("ball", Sphere(0.05), translation(*(top + [0, 0, 0.04])))  # dips into the mesh
    scene.add_object("rod", Capsule(0.02, 0.5), translation(*(top + [0, 0, 0.3])))  # touches the ball
    scene.add_object("crate", Box(0.2, 0.2, 0.2), translation(5, 5, 5))  # far from all
    hit, names, data = scene.in_collision_internal(return_names=True, return_data=True)
    assert hit and names == {("ball", "elephant"), ("ball", "rod")}
    for contact in data:
        assert "ball" in contact.names
        assert np.linalg.norm(contact.point - (top + [0, 0, 0.04])) <= 0.05 + 1e-12  # in the ball
        if "elephant" in contact.names:
            assert contact.index("ball") is None and contact.index("elephant") >= 0
        else:
            assert contact.triangles == (None, None)
    # The closest pairs agree with the pair queries.
    distance, pair = scene.min_distance_internal(return_names=True)
    assert distance == 0 and pair in {("ball", "elephant"), ("ball", "rod")}
    crate = scene.min_distance_single(elephant, translation(5, 5, 5.5), return_name=True)
    assert crate[1] == "crate"
    gap = tightbvh.distance_shape(Box(0.2, 0.2, 0.2), translation(5, 5, 5), tightbvh.Model(elephant),
                                  translation(5, 5, 5.5))
    assert crate[0] == pytest.approx(gap.distance, rel=1e-12)
    with pytest.raises(ValueError, match="is a shape"):
        scene.model("ball")
    # Pickled with its shapes, the scene answers the same.
    again = pickle.loads(pickle.dumps(scene))
    assert again.in_collision_internal(return_names=True)[1] == names
    assert pickle.loads(pickle.dumps(Capsule(0.02, 0.5))).length == 0.5
    result = tightbvh.collide_shape(Sphere(0.05), translation(*top), elephant_model, all_pairs=True)
    copied = pickle.loads(pickle.dumps(result))
    assert copied.hit == result.hit and copied.triangles.tolist() == result.triangles.tolist()
    far = tightbvh.distance_shape(Sphere(0.05), translation(3, 0, 0), elephant_model)
    assert pickle.loads(pickle.dumps(far)).point_mesh.tolist() == far.point_mesh.tolist()


def test_a_shape_as_the_query_object(elephant, elephant_model):
    # The *_single calls and in_collision_batch take a shape where they take a mesh: the same
    # answers as the pair calls against each object.
    scene = tightbvh.Scene()
    scene.add_object("elephant", elephant_model)
    top = elephant.vertices[np.argmax(elephant.vertices[:, 2])]
    scene.add_object("rod", Capsule(0.02, 0.5), translation(*(top + [0, 0, 0.6])))
    probe = Sphere(0.05)
    at_top = translation(*(top + [0, 0, 0.04]))  # dips into the elephant, 0.2 below the rod
    hit, names, data = scene.in_collision_single(probe, at_top, return_names=True, return_data=True)
    assert hit and names == {"elephant"}
    assert all(c.index("__external") is None and c.index("elephant") >= 0 for c in data)
    assert tightbvh.distance_shape(probe, at_top, elephant_model).distance == 0
    within = scene.distance_within_single(probe, 0.5, at_top)
    assert set(within) == {"elephant", "rod"}
    assert within["rod"] == pytest.approx(0.6 - 0.25 - 0.02 - 0.04 - 0.05, rel=1e-12)
    above = translation(*(top + [0, 0, 0.2]))
    distance, name, info = scene.min_distance_single(probe, above, return_name=True, return_data=True)
    assert name == "rod" and distance == pytest.approx(0.6 - 0.25 - 0.02 - 0.2 - 0.05, rel=1e-12)
    assert info.index("__external") is None and info.index("rod") is None
    batch = scene.in_collision_batch(probe, np.stack([at_top, above, translation(9, 9, 9)]))
    assert batch == [{"elephant"}, set(), set()]
    # A fitted Box as the query object: its own pose is composed with the transform. It holds the
    # elephant and stays below the rod (whose lowest point is 0.33 above the elephant's top).
    fitted = tightbvh.fit(elephant.vertices)
    assert scene.in_collision_single(fitted, return_names=True)[1] == {"elephant"}
    assert scene.in_collision_batch(fitted, np.stack([np.eye(4), translation(9, 9, 9)])) == [{"elephant"}, set()]
    with pytest.raises(ValueError):
        scene.in_collision_single(probe, np.full((4, 4), np.nan))


class _Attributes:
    """A stand-in for trimesh's PrimitiveAttributes: plain attributes."""

    def __init__(self, **values):
        self.__dict__.update(values)


def _trimesh_like(kind, mesh, **primitive):
    """A stand-in for trimesh.primitives.<kind> (trimesh is not in Debian 12): a class of that name in
    the module trimesh.primitives with trimesh 4's `primitive` attributes, and tessellated vertices
    and faces (here a decoy mesh far away, so that using them instead of the primitive shows)."""
    cls = type(kind, (), {"__module__": "trimesh.primitives"})
    obj = cls()
    obj.primitive = _Attributes(**primitive)
    obj.vertices, obj.faces = mesh.vertices + 100.0, mesh.faces
    return obj


def test_trimesh_primitives_stay_exact(elephant, elephant_model, unit_cube):
    top = elephant.vertices[np.argmax(elephant.vertices[:, 2])]
    place = translation(*(top + [0, 0, 0.04]))
    tilted = pose_matrix(rotation([0.3, -0.2, 0.9], 0.7), top + [0, 0, 0.01])
    pairs = [
        (_trimesh_like("Sphere", unit_cube, radius=0.05, transform=place), Sphere(0.05), place),
        (_trimesh_like("Sphere", unit_cube, radius=0.05, center=top + [0, 0, 0.04]), Sphere(0.05), place),
        (_trimesh_like("Box", unit_cube, extents=np.array([0.1, 0.2, 0.05]), transform=tilted),
         Box(0.1, 0.2, 0.05), tilted),
        (_trimesh_like("Capsule", unit_cube, radius=0.02, height=0.3, transform=tilted), Capsule(0.02, 0.3), tilted),
    ]
    for primitive, shape, pose in pairs:
        want = tightbvh.collide_shape(shape, pose, elephant_model, all_pairs=True)
        assert want.hit
        # The primitive's own transform places it; a transform given with it moves it further.
        got = tightbvh.collide_shape(primitive, None, elephant_model, all_pairs=True)
        assert got.triangles.tolist() == want.triangles.tolist()
        far = tightbvh.distance_shape(primitive, translation(0, 0, 3), elephant_model)
        assert far.distance == pytest.approx(
            tightbvh.distance_shape(shape, translation(0, 0, 3) @ pose, elephant_model).distance, rel=1e-12)
        scene = tightbvh.Scene()
        scene.add_object("elephant", elephant_model)
        scene.add_object("part", primitive)
        assert scene.in_collision_internal()
        with pytest.raises(ValueError, match="is a shape"):
            scene.model("part")
    # A scaled primitive is not a rigid shape: its mesh stands for it (here the decoy, far away).
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    with pytest.raises(TypeError):
        tightbvh.collide_shape(_trimesh_like("Sphere", unit_cube, radius=0.05, transform=scaled), None, elephant_model)
    with pytest.raises(ValueError, match="radius"):
        tightbvh.collide_shape(_trimesh_like("Sphere", unit_cube, radius=-1.0, transform=place), None, elephant_model)


def test_cylinder_and_convex(elephant, elephant_model, unit_cube):
    import pickle

    from tightbvh.shapes import Convex, Cylinder

    # An upright cylinder above the cube [-1, 1]^3: the gap is its bottom's height over the top face.
    upright = Cylinder(0.3, 0.8)
    for z, want in [(1.5, 0.1), (1.4, 0.0), (1.2, 0.0)]:
        d = tightbvh.distance_shape(upright, translation(0.2, -0.1, z), tightbvh.Model(unit_cube))
        assert d.distance == pytest.approx(want, abs=1e-9)
        assert tightbvh.collide_shape(upright, translation(0.2, -0.1, z), tightbvh.Model(unit_cube)).hit == (want == 0)
    # The hull of a box's corners is that box: the same triangles touch, at the same distance.
    corners = np.array([[x, y, z] for x in (-0.05, 0.05) for y in (-0.1, 0.1) for z in (-0.025, 0.025)])
    hull = Convex(corners)
    assert hull.vertices.shape == (8, 3) and hull.faces.shape == (12, 3)
    top = elephant.vertices[np.argmax(elephant.vertices[:, 2])]
    for lift in (0.01, 0.2):
        pose = pose_matrix(rotation([0.3, -0.2, 0.9], 0.7), top + [0, 0, lift])
        a = tightbvh.collide_shape(hull, pose, elephant_model, all_pairs=True)
        b = tightbvh.collide_shape(Box(0.1, 0.2, 0.05), pose, elephant_model, all_pairs=True)
        assert a.triangles.tolist() == b.triangles.tolist()
        assert tightbvh.distance_shape(hull, pose, elephant_model).distance == pytest.approx(
            tightbvh.distance_shape(Box(0.1, 0.2, 0.05), pose, elephant_model).distance, rel=1e-12, abs=1e-15)
    # In a scene, pickled with it; trimesh's Cylinder primitive is a Cylinder.
    scene = tightbvh.Scene()
    scene.add_object("elephant", elephant_model)
    scene.add_object("can", upright, translation(*(top + [0, 0, 0.6])))
    scene.add_object("rock", hull, translation(*(top + [0, 0, 0.01])))
    names = scene.in_collision_internal(return_names=True)[1]
    assert names == {("elephant", "rock")}
    assert pickle.loads(pickle.dumps(scene)).in_collision_internal(return_names=True)[1] == names
    again = pickle.loads(pickle.dumps(hull))
    assert again.vertices.shape == hull.vertices.shape
    can = _trimesh_like("Cylinder", unit_cube, radius=0.3, height=0.8, transform=translation(0.2, -0.1, 1.5))
    assert tightbvh.distance_shape(can, None, tightbvh.Model(unit_cube)).distance == pytest.approx(0.1, abs=1e-9)
    # Bad input names what is wrong.
    with pytest.raises(ValueError):
        Convex(corners[:3])
    with pytest.raises(ValueError):
        Convex(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float))  # flat
    with pytest.raises(ValueError):
        Convex(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, np.nan]]))
    with pytest.raises(ValueError, match="radius"):
        Cylinder(-1.0, 1.0)
