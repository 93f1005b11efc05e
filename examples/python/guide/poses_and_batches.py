"""The user guide's Python samples: poses as 4x4 matrices or (R, t) pairs, contacts, a batch of poses,
distance with an upper bound, saving a tree, and the errors bad input raises.
Run by tests/python/test_guide_samples.py."""
import pathlib
import tempfile

import numpy as np
import tightbvh

meshes = pathlib.Path(__file__).resolve().parents[3] / "meshes"
a = tightbvh.load_mesh(meshes / "knot1.off")
b = tightbvh.load_mesh(meshes / "elephant.off")
tree_a = tightbvh.build(a)  # auto, rapid split, one triangle per leaf, all cores
tree_b = tightbvh.build(b, fitter="approx", split="median", leaf_size=4)

# A pose is a 4x4 matrix (last row 0 0 0 1), an (R, t) pair, or None (the identity).
angle = 0.5
R = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
t = np.array([0.1, 0.0, 0.0])
pose = np.eye(4)
pose[:3, :3], pose[:3, 3] = R, t
same = tightbvh.collide(tree_a, None, None, tree_b, None, (R, t), all_pairs=True)  # None: the tree's mesh
result = tightbvh.collide(tree_a, a, None, tree_b, b, pose, all_pairs=True)
print(f"touching pairs: {len(result.pairs)} (the same with (R, t): {np.array_equal(result.pairs, same.pairs)})")

# Where they cross: contacts=True (with all_pairs) adds one row per pair: its segment (a point
# is stored twice, a coplanar polygon's row is NaN), both unit face normals, the kind
# (tightbvh.CONTACT_KINDS) and the intersection curve's length.
crossing = tightbvh.collide(tree_a, a, None, tree_b, b, pose, all_pairs=True, contacts=True)
segments = crossing.segments[crossing.kind == 2]  # (K, 2, 3): the intersection curve
print(f"intersection curve: {len(segments)} segments, {crossing.curve_length:.4f} long")
lengths = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
if not np.array_equal(crossing.pairs, result.pairs) or not np.isclose(lengths.sum(), crossing.curve_length):
    raise SystemExit("contacts: not one per pair, or the curve's length is not the segments' sum")

# Many poses in one call: (N, 4, 4) or (Rs (N, 3, 3), ts (N, 3)); the same answers on any thread count.
poses = np.tile(np.eye(4), (64, 1, 1))
poses[:, 0, 3] = np.linspace(0.0, 1.5, 64)
hits, pair_counts = tightbvh.collide_batch(tree_a, a, None, tree_b, b, poses, threads=0)
print(f"{hits.sum()} of {len(hits)} poses hit")

# How far apart, but only if closer than 0.5.
gap = tightbvh.distance(tree_a, a, None, tree_b, b, poses[-1], upper_bound=0.5)
print("distance: at least 0.5" if gap.beyond_upper_bound else f"distance: {gap.distance:.4f}")

# Save and load a tree (the versioned tree format); the loaded tree needs its mesh again.
with tempfile.TemporaryDirectory() as folder:
    tree_a.save(pathlib.Path(folder) / "knot1.tree")
    loaded = tightbvh.Tree.load(pathlib.Path(folder) / "knot1.tree", mesh=a)
    print(f"loaded {loaded.node_count} nodes, valid: {bool(loaded.validate())}")

# Bad input: ValueError (bad values, naming the argument) or TypeError (wrong kinds of objects).
try:
    tightbvh.collide(tree_a, a, None, tree_b, b, np.diag([1.0, 1.0, -1.0, 1.0]))
except ValueError as error:
    print(f"ValueError: {error}")
