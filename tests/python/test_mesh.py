"""Mesh, load_mesh, as_mesh: conversions, read-only views, trimesh-like objects, input errors."""
import gc

import numpy as np
import pytest
import tightbvh
from conftest import MESHES, tetrahedron


class TrackedArray(np.ndarray):
    """Like trimesh's TrackedArray: an ndarray subclass."""


class FakeTrimesh:
    """What tightbvh needs of a trimesh.Trimesh: .vertices and .faces."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices, dtype=np.float64).view(TrackedArray)
        self.faces = np.asarray(faces, dtype=np.int64).view(TrackedArray)


def test_mesh_copies_arrays_into_readonly_views():
    v, f = tetrahedron()
    mesh = tightbvh.Mesh(v, f)
    assert mesh.vertex_count == 4 and mesh.face_count == 4
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (4, 3)
    assert mesh.faces.dtype == np.uint32 and mesh.faces.shape == (4, 3)
    np.testing.assert_array_equal(mesh.vertices, v)
    np.testing.assert_array_equal(mesh.faces, f)
    v[0, 0] = 5.0  # the mesh holds a copy
    assert mesh.vertices[0, 0] == 0.0
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 1.0  # read-only: trees rely on their mesh not changing
    with pytest.raises(ValueError):
        mesh.faces[0, 0] = 1


def test_views_keep_the_mesh_alive():
    v, f = tetrahedron()
    vertices = tightbvh.Mesh(v, f).vertices
    gc.collect()
    np.testing.assert_array_equal(vertices, tetrahedron()[0])


def test_mesh_accepts_lists_integer_vertices_and_strided_arrays():
    v, f = tetrahedron()
    reference = tightbvh.Mesh(v, f)
    from_lists = tightbvh.Mesh(v.astype(int).tolist(), f.tolist())
    np.testing.assert_array_equal(from_lists.vertices, reference.vertices)
    wide = np.zeros((4, 6))
    wide[:, ::2] = v  # non-contiguous columns
    faces_f = np.asfortranarray(f.astype(np.uint16))
    strided = tightbvh.Mesh(wide[:, ::2], faces_f)
    np.testing.assert_array_equal(strided.vertices, reference.vertices)
    np.testing.assert_array_equal(strided.faces, reference.faces)
    readonly = v.copy()
    readonly.flags.writeable = False
    np.testing.assert_array_equal(tightbvh.Mesh(readonly, f).vertices, v)


def test_load_mesh_matches_the_off_file():
    path = MESHES / "elephant.off"
    mesh = tightbvh.load_mesh(str(path))
    lines = path.read_text().split("\n")
    n, m, _ = map(int, lines[1].split())
    numbers = " ".join(lines[2:]).split()
    vertices = np.array(numbers[: 3 * n], dtype=np.float64).reshape(n, 3)
    faces = np.array(numbers[3 * n : 3 * n + 4 * m], dtype=np.int64).reshape(m, 4)[:, 1:]
    np.testing.assert_array_equal(mesh.vertices, vertices)  # OFF keeps the file's doubles and order
    np.testing.assert_array_equal(mesh.faces, faces)
    assert tightbvh.load_mesh(path).face_count == m  # pathlib paths too


def test_trimesh_like_objects_are_meshes():
    v, f = tetrahedron()
    duck = FakeTrimesh(v, f)
    mesh = tightbvh.as_mesh(duck)
    assert isinstance(mesh, tightbvh.Mesh)
    np.testing.assert_array_equal(mesh.vertices, v)
    assert tightbvh.as_mesh(mesh) is mesh
    tree = tightbvh.build(duck, fitter="pca")
    assert tree.validate()
    assert tightbvh.collide(tree, duck, None, tree, duck, None).hit
    with pytest.raises(TypeError, match="mesh: expected a tightbvh.Mesh or an object with .vertices and .faces"):
        tightbvh.as_mesh(42)


@pytest.mark.parametrize(
    "vertices, faces, error, message",
    [
        (np.zeros((4, 2)), [[0, 1, 2]], ValueError, r"vertices: expected shape \(N, 3\), got \(4, 2\)"),
        (np.zeros(12), [[0, 1, 2]], ValueError, r"vertices: expected shape \(N, 3\), got \(12,\)"),
        (np.zeros((4, 3)), [[0, 1]], ValueError, r"faces: expected shape \(M, 3\), got \(1, 2\)"),
        (np.zeros((4, 3), dtype=complex), [[0, 1, 2]], TypeError, "vertices: expected real numbers.*complex128"),
        ([["a", "b", "c"]], [[0, 0, 0]], TypeError, "vertices: expected real numbers"),
        (None, [[0, 1, 2]], TypeError, "vertices: expected real numbers.*object"),
        (np.zeros((4, 3), dtype=bool), [[0, 1, 2]], TypeError, "vertices: .*bool"),
        (np.zeros((4, 3)), [[0.0, 1.0, 2.0]], TypeError, "faces: expected integer vertex indices, got dtype float64"),
        (np.zeros((4, 3)), [[0, 1, 4]], ValueError, r"faces: row 0 has vertex index 4, out of range \(there are 4"),
        (np.zeros((4, 3)), [[0, 1, 2], [0, -1, 2]], ValueError, "faces: row 1 has vertex index -1, out of range"),
        (np.zeros((4, 3)), np.array([[0, 1, 2**63]], dtype=np.uint64), ValueError, "faces: row 0 .*9223372036854775808"),
        (np.zeros((4, 3)), np.zeros((0, 3), dtype=int), ValueError, "Mesh: no triangles"),
        ([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], [[0, 1, 2]], ValueError, "vertices: row 1 has a non-finite"),
        ([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], [[0, 1, 2]], ValueError, "vertices: row 2 has a non-finite"),
        ([[0, 0, 0], [1, 0]], [[0, 1, 2]], ValueError, "vertices: cannot be read as an array"),
    ],
)
def test_mesh_input_errors(vertices, faces, error, message):
    with pytest.raises(error, match=message):
        tightbvh.Mesh(vertices, faces)


def test_load_mesh_errors_are_value_errors_naming_the_file(tmp_path):
    with pytest.raises(ValueError, match="missing.off"):
        tightbvh.load_mesh(tmp_path / "missing.off")
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    with pytest.raises(ValueError, match="bad.off"):
        tightbvh.load_mesh(bad)
    with pytest.raises(TypeError):
        tightbvh.load_mesh(3)
