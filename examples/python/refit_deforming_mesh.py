"""A deforming mesh: twist A a little more every frame, refit its tree (same topology, boxes fitted
again to the moved triangles: much cheaper than a new build), and collide it against B. Each
frame's pairs are checked against a tree built from scratch; exit code 1 if they differ.
(The Python twin of examples/refit_deforming_mesh.cpp.) Usage: refit_deforming_mesh.py [MESH_A MESH_B]"""
import pathlib
import sys

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
path_a, path_b = sys.argv[1:3] if len(sys.argv) > 2 else (meshes / "elephant.off", meshes / "knot1.off")

rest = tightbvh.load_mesh(path_a)  # A's undeformed shape
b = tightbvh.load_mesh(path_b)
tree_a = tightbvh.build(rest, fitter="pca")  # pca is refit's default fitter (its fast path)
tree_b = tightbvh.build(b)

pose_b = np.eye(4)  # B in A's frame, fixed; A moves by deforming
pose_b[:3, 3] = [0.2, 0.0, 0.0]
center = (rest.vertices.min(axis=0) + rest.vertices.max(axis=0)) / 2

frames = 8
for frame in range(frames):
    # Twist about the vertical axis through A's center: the turn grows with the height.
    twist = 1.5 * frame / (frames - 1)  # radians per unit of height
    p = rest.vertices - center
    angle = twist * p[:, 1]
    c, s = np.cos(angle), np.sin(angle)
    moved = center + np.column_stack([c * p[:, 0] + s * p[:, 2], p[:, 1], -s * p[:, 0] + c * p[:, 2]])
    a = tightbvh.Mesh(moved, rest.faces)  # the same triangles, moved vertices

    tree_a = tightbvh.refit(tree_a, a)  # a new tree: the old topology, every box fitted again
    result = tightbvh.collide(tree_a, a, None, tree_b, b, pose_b, all_pairs=True)

    # The check: a tree built from scratch on this frame's mesh finds exactly the same pairs.
    fresh = tightbvh.collide(tightbvh.build(a, fitter="pca"), a, None, tree_b, b, pose_b, all_pairs=True)
    print(f"frame {frame}: twist {twist:.2f} rad, {len(result.pairs)} touching pairs, "
          f"{result.stats['box_tests']} box tests (fresh build: {fresh.stats['box_tests']})")
    if not np.array_equal(result.pairs, fresh.pairs):
        sys.exit(f"refit_deforming_mesh.py: frame {frame}: the refitted tree's pairs differ from a fresh build's")

print(f"refitted tree agrees with fresh builds on all {frames} frames")
