"""How far apart are two posed meshes, and where: the distance, the closest triangles and points
(world frame and each mesh's own), then the cheaper variants: an error bound and an upper bound.
Every answer is checked against the brute-force reference (every triangle pair); exit code 1 if one
is wrong. A is cut to its first 800 triangles so that the reference stays fast.
(The Python twin of examples/distance_closest_points.cpp.) Usage: distance_closest_points.py [MESH_A MESH_B]"""
import math
import pathlib
import sys

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
path_a, path_b = sys.argv[1:3] if len(sys.argv) > 2 else (meshes / "elephant.off", meshes / "knot1.off")

whole_a = tightbvh.load_mesh(path_a)
a = tightbvh.Mesh(whole_a.vertices, whole_a.faces[:800])  # unused vertices are allowed
b = tightbvh.load_mesh(path_b)
tree_a, tree_b = tightbvh.build(a), tightbvh.build(b)

# Both meshes posed in the world (4x4 matrices): A lifted, B turned 30 degrees about z and moved along x.
pose_a = np.eye(4)
pose_a[:3, 3] = [0.0, 0.0, 0.5]
c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
pose_b = np.array([[c, -s, 0, 1.2], [s, c, 0, 0.0], [0, 0, 1, 0.5], [0, 0, 0, 1]])

d = tightbvh.distance(tree_a, a, pose_a, tree_b, b, pose_b)
print(f"distance {d.distance:.9f} between triangle {d.triangles[0]} of A and triangle {d.triangles[1]} of B")
print(f"  closest points (world): A {np.round(d.point_a, 4)}  B {np.round(d.point_b, 4)}")
print(f"  the same in each mesh's frame: A {np.round(d.point_a_local, 4)}  B {np.round(d.point_b_local, 4)}")

# Cheaper queries: stop once within 5% of the minimum, or once nothing is closer than a bound.
rough = tightbvh.distance(tree_a, a, pose_a, tree_b, b, pose_b, relative_error=0.05)
far = tightbvh.distance(tree_a, a, pose_a, tree_b, b, pose_b, upper_bound=0.5 * d.distance)
print(f"within 5%: {rough.distance:.9f} ({rough.stats['triangle_pairs']} triangle pairs measured, exact: "
      f"{d.stats['triangle_pairs']}); below {0.5 * d.distance:.4f}: "
      f"{'nothing closer' if far.beyond_upper_bound else 'closer'}")

# The checks: the reference's distance, points that are the distance apart and map to the local
# ones by the poses, the error bound kept, and the upper bound reported.
reference = tightbvh.distance_brute_force(a, pose_a, b, pose_b)
tolerance = 1e-12 * (1.0 + d.distance)
ok = (abs(d.distance - reference.distance) <= tolerance
      and abs(np.linalg.norm(d.point_a - d.point_b) - d.distance) <= tolerance
      and np.allclose(pose_a[:3, :3] @ d.point_a_local + pose_a[:3, 3], d.point_a, rtol=0, atol=tolerance)
      and np.allclose(pose_b[:3, :3] @ d.point_b_local + pose_b[:3, 3], d.point_b, rtol=0, atol=tolerance)
      and reference.distance - tolerance <= rough.distance <= 1.05 * reference.distance + tolerance
      and far.beyond_upper_bound and far.distance == 0.5 * d.distance)
print(f"brute force: {reference.distance:.9f} over {reference.stats['triangle_pairs']} triangle pairs: "
      f"{'agrees' if ok else 'DISAGREES'}")
sys.exit(0 if ok else 1)
