"""Primitive shapes against a mesh, without tessellating them: which triangles a sphere, a
capsule and a box touch, and how far they are. The answers are checked against the point queries
(a sphere is its center grown by the radius); exit code 1 if one is wrong.
Usage: shapes_against_a_mesh.py [MESH]"""
import pathlib
import sys

import numpy as np
import tightbvh
from tightbvh.shapes import Box, Capsule, Sphere

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
model = tightbvh.Model(sys.argv[1] if len(sys.argv) > 1 else meshes / "elephant.off")

# FCL's conventions: each shape centered in its frame, the capsule along its z axis; a pose is a
# 4x4 matrix (or None), the model's too.
pose = np.eye(4)
pose[:3, 3] = model.mesh.vertices[0] + [0.0, 0.0, 0.02]  # just above a vertex of the mesh
touching = tightbvh.collide_shape(Capsule(radius=0.03, length=0.2), pose, model, all_pairs=True)
print(f"capsule: {len(touching.triangles)} triangles touch it")
gap = tightbvh.distance_shape(Sphere(0.01), pose, model)
print(f"sphere: distance {gap.distance:.6f}, closest triangle {gap.triangle}")
box = tightbvh.distance_shape(Box(0.1, 0.1, 0.1), None, model)  # None: at the origin, unturned
print(f"box at the origin: distance {box.distance:.6f}{' (touching)' if box.intersecting else ''}")

# Check: the sphere's distance is its center's distance less the radius.
_, center_distance, _ = model.closest_points(pose[:3, 3][None, :])
wrong = not np.isclose(gap.distance, max(0.0, center_distance[0] - 0.01), rtol=1e-12, atol=1e-15)
wrong |= not touching.hit
print("checks: " + ("WRONG" if wrong else "agree"))
sys.exit(1 if wrong else 0)
