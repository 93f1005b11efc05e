"""trimesh's CollisionManager code on tightbvh.Scene: the same calls, one line changed.

Three unit cubes (any object with .vertices and .faces works, such as a trimesh.Trimesh) and a
probe; prints which objects touch and how far the probe is from the closest one, then checks the
answers against the pair queries (exit status 1 when one differs).
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
# manager = trimesh.collision.CollisionManager()
manager = tightbvh.Scene()
manager.add_object("left", cube)
manager.add_object("middle", cube, transform=moved(0.5, 0.5))
manager.add_object("right", cube, transform=moved(3.0))

hit, pairs = manager.in_collision_internal(return_names=True)
print("touching:", hit, sorted(pairs))
gap, name = manager.min_distance_single(cube, transform=moved(0.0, 0.0, 2.5), return_name=True)
print(f"probe: {gap:.3f} from {name}")
manager.set_transform("right", moved(1.25))
print("after the move:", sorted(manager.in_collision_internal(return_names=True)[1]))

# The same answers from the pair queries over every object pair.
tree = tightbvh.build(cube)
poses = {n: manager.transform(n) for n in manager.names}
expected = {(a, b) for a, b in itertools.combinations(sorted(poses), 2)
            if tightbvh.collide(tree, None, poses[a], tree, None, poses[b]).hit}
closest = min(tightbvh.distance(tree, None, poses[n], tree, None, moved(0.0, 0.0, 2.5)).distance for n in poses)
if expected != manager.in_collision_internal(return_names=True)[1] or abs(closest - gap) > 1e-12:
    sys.exit("the scene and the pair queries differ")
print(f"{manager.model_count} model for {len(manager)} objects; pair queries agree")
