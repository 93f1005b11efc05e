"""Point queries against a posed mesh: the closest point on the surface of each of many points,
the signed distance (NEGATIVE INSIDE, the opposite of trimesh's proximity.signed_distance) and
whether each point is inside. The answers are checked against a brute force in NumPy (every
triangle) and against each other; exit code 1 if one is wrong. Usage: point_queries.py [MESH]"""
import pathlib
import sys

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
path = sys.argv[1] if len(sys.argv) > 1 else meshes / "fandisk.off"

model = tightbvh.Model(path)
pose = np.eye(4)
pose[:3, 3] = [10.0, 0.0, 0.0]  # the mesh moved 10 along x
rng = np.random.default_rng(1)
points = rng.uniform(-0.6, 0.6, (2000, 3)) + pose[:3, 3]  # world frame

# trimesh's names and shapes: (closest (N, 3), distance (N,), triangle_id (N,)), plus barycentric.
closest, distance, triangle_id, barycentric = model.closest_points(points, transform=pose, return_barycentric=True)
signed = model.signed_distance(points, transform=pose)  # negative inside, 0 on the surface
inside = model.contains(points, transform=pose)  # strictly inside; return_on_surface=True for both
print(f"{len(points)} points: {inside.sum()} inside, distances {distance.min():.4f} to {distance.max():.4f}")


def point_triangle_distances(p, corners):
    """Distance from point p (3,) to every triangle (T, 3 corners, 3): the plane when the projection
    is inside the triangle, else the nearest of the three edges."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    height = np.einsum("ij,ij->i", p - a, n)
    q = p - height[:, None] * n
    inside_face = np.ones(len(a), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside_face &= np.einsum("ij,ij->i", np.cross(v - u, q - u), n) >= 0
    best = np.where(inside_face, np.abs(height), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        t = np.clip(np.einsum("ij,ij->i", p - u, v - u) / np.einsum("ij,ij->i", v - u, v - u), 0, 1)
        best = np.minimum(best, np.linalg.norm(p - (u + t[:, None] * (v - u)), axis=1))
    return best


corners = model.mesh.vertices[model.mesh.faces] + pose[:3, 3]  # every triangle, world frame
wrong = 0
for i in range(0, len(points), 50):  # a sample: the brute force is slow
    wrong += not np.isclose(point_triangle_distances(points[i], corners).min(), distance[i], rtol=1e-9, atol=1e-12)
wrong += not np.allclose(np.einsum("nk,nkj->nj", barycentric, corners[triangle_id]), closest, atol=1e-12)
wrong += not np.allclose(np.linalg.norm(points - closest, axis=1), distance, rtol=1e-12)
wrong += not np.array_equal(signed < 0, inside) or not np.array_equal(np.abs(signed), distance)
print("brute force and signs: " + ("agree" if wrong == 0 else f"{wrong} checks failed"))
sys.exit(1 if wrong else 0)
