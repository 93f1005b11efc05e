"""Collide two meshes and print the touching triangle pairs (the Python twin of
examples/collide_two_meshes.cpp), then their distance once moved apart. Usage: collide_two_meshes.py [MESH_A MESH_B]"""
import pathlib
import sys

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
path_a, path_b = sys.argv[1:3] if len(sys.argv) > 2 else (meshes / "elephant.off", meshes / "knot1.off")

# A Model: the mesh, its tree and the tree's wide float nodes (the fast route for queries). It
# takes a path, a tightbvh.Mesh or any object with .vertices and .faces, e.g. a trimesh.Trimesh.
a = tightbvh.Model(path_a, fitter="approx")
b = tightbvh.Model(path_b)  # the default fitter: auto

pose_b = np.eye(4)  # B in A's frame: a 4x4 matrix, a (R, t) pair, or None
pose_b[:3, 3] = [0.2, 0.0, 0.0]
result = tightbvh.collide(a, None, b, pose_b, all_pairs=True)

print(f"{'hit' if result.hit else 'no hit'}: {len(result.pairs)} touching triangle pairs "
      f"({result.stats['box_tests']} box tests, {result.stats['triangle_tests']} triangle tests)")
for triangle_a, triangle_b in result.pairs[:10]:
    print(f"  triangle {triangle_a} of A touches triangle {triangle_b} of B")

# Moved apart: how far, and where (closest points in the world frame, here A's).
pose_b[:3, 3] = [1.5, 0.0, 0.0]
gap = tightbvh.distance(a, None, b, pose_b)
print(f"at x = 1.5: distance {gap.distance:.6f} between triangle {gap.triangles[0]} of A and "
      f"{gap.triangles[1]} of B, from {np.round(gap.point_a, 4)} to {np.round(gap.point_b, 4)}")
