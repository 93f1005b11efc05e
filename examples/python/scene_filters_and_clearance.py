"""Collision filter bits and the clearance report of tightbvh.Scene.

Two robot links, a shelf, a wall and a table (unit cubes and one slab). Filter bits keep the
robot's links from being tested against each other and the fixed objects against each other;
distance_within_internal lists every tested pair closer than a clearance, with its distance.
The answers are checked against the pair queries on every object pair (exit status 1 when one
differs).
"""
import itertools
import sys
import types

import numpy as np

import tightbvh


def unit_cube():
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return types.SimpleNamespace(vertices=corners, faces=faces)


def moved(x, y=0.0, z=0.0):
    transform = np.eye(4)
    transform[:3, 3] = (x, y, z)
    return transform


cube = unit_cube()
ROBOT, FIXED = 1, 2  # filter groups: one bit each
scene = tightbvh.Scene()
# A pair is tested when each one's group meets the other's mask: links meet fixed objects only.
scene.add_object("link0", cube, moved(0.0), group=ROBOT, mask=FIXED)
scene.add_object("link1", cube, moved(0.8), group=ROBOT, mask=FIXED)  # overlaps link0: not tested
scene.add_object("shelf", cube, moved(1.9), group=FIXED, mask=ROBOT)
scene.add_object("wall", cube, moved(2.95), group=FIXED, mask=ROBOT)
scene.add_object("table", cube, moved(0.0, 0.0, -1.02), group=FIXED, mask=ROBOT)

print("touching:", scene.in_collision_internal())
clearance = scene.distance_within_internal(0.15)
print("closer than 0.15:", ", ".join(f"{a}-{b} {d:.3f}" for (a, b), d in clearance.items()))
scene.set_filter("wall", FIXED, ROBOT | FIXED)  # the wall now meets the shelf too ...
scene.set_filter("shelf", FIXED, ROBOT | FIXED)  # ... when both masks say so
print("with the wall:", ", ".join(f"{a}-{b} {d:.3f}" for (a, b), d in scene.distance_within_internal(0.15).items()))

# The same answers from the pair queries over every object pair that the filters let through.
tree = tightbvh.build(cube)
expected = {}
for a, b in itertools.combinations(sorted(scene.names), 2):
    (group_a, mask_a), (group_b, mask_b) = scene.filter(a), scene.filter(b)
    if group_a & mask_b and group_b & mask_a:
        d = tightbvh.distance(tree, None, scene.transform(a), tree, None, scene.transform(b)).distance
        if d < 0.15:
            expected[(a, b)] = d
got = scene.distance_within_internal(0.15)
if got.keys() != expected.keys() or any(abs(got[k] - expected[k]) > 1e-12 for k in got):
    sys.exit("the scene and the pair queries differ")
print(f"{len(got)} pairs within 0.15; pair queries agree")
