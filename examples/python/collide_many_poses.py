"""Many poses of B at once: one collide_batch (and one distance_batch) call spreads the queries over
threads, releases the GIL, and returns NumPy arrays in pose order, the same for any thread count.
Checked against one single query per pose; exit code 1 if any differs.
(The Python twin of examples/collide_many_poses.cpp.) Usage: collide_many_poses.py [MESH_A MESH_B]"""
import pathlib
import sys

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
path_a, path_b = sys.argv[1:3] if len(sys.argv) > 2 else (meshes / "elephant.off", meshes / "knot1.off")

a = tightbvh.load_mesh(path_a)
b = tightbvh.load_mesh(path_b)
tree_a, tree_b = tightbvh.build(a), tightbvh.build(b)

# 64 poses of B, (64, 4, 4), on a widening spiral around A, turning about y as it goes: near ones
# touch, far ones not.
n = 64
angle = 0.4 * np.arange(n)
radius = 1.5 * np.arange(n) / n
poses = np.tile(np.eye(4), (n, 1, 1))
poses[:, 0, 0] = poses[:, 2, 2] = np.cos(angle)
poses[:, 0, 2], poses[:, 2, 0] = np.sin(angle), -np.sin(angle)
poses[:, :3, 3] = np.column_stack([radius * np.cos(angle), np.zeros(n), radius * np.sin(angle)])

# One call each, on 2 threads (0 would take every core). A stays at the identity (None).
hits, pair_counts = tightbvh.collide_batch(tree_a, a, None, tree_b, b, poses, all_pairs=True, threads=2)
distances, triangles, points_a, points_b = tightbvh.distance_batch(tree_a, a, None, tree_b, b, poses, threads=2)

# The check: entry i is the answer of a single query at pose i.
for i in range(n):
    one = tightbvh.collide(tree_a, a, None, tree_b, b, poses[i], all_pairs=True)
    gap = tightbvh.distance(tree_a, a, None, tree_b, b, poses[i])
    same = (hits[i], pair_counts[i], distances[i]) == (one.hit, len(one.pairs), gap.distance)
    if not same or hits[i] != (gap.distance == 0):
        sys.exit(f"collide_many_poses.py: pose {i}: the batch answer differs from the single query")
    if i % 16 == 0:
        print(f"pose {i:2d}: {'hit' if hits[i] else 'no hit'}, {pair_counts[i]} pairs, distance {distances[i]:.6f}")
print(f"{n} poses on 2 threads: {hits.sum()} touching, {n - hits.sum()} apart, equal to {n} single queries")
