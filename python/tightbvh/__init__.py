"""tightbvh: bounding-volume hierarchies of tight oriented boxes over triangle meshes.

NumPy arrays in and out. A mesh argument is a tightbvh.Mesh or any object with .vertices (N, 3)
and .faces (M, 3) arrays (a trimesh.Trimesh); a pose is a 4x4 matrix, a (R, t) pair or None.
Bad input raises ValueError or TypeError naming the argument.

    import tightbvh
    a = tightbvh.load_mesh("meshes/elephant.off")
    tree_a = tightbvh.build(a, fitter="approx")
    box = tightbvh.fit(a.vertices, method="exact")
    result = tightbvh.collide(tree_a, a, None, tree_b, b, pose_b, all_pairs=True)
    gap = tightbvh.distance(tree_a, a, None, tree_b, b, pose_b)  # .distance, .point_a, .point_b
    scene = tightbvh.Scene()  # the methods of trimesh.collision.CollisionManager
    hit = tightbvh.collide_shape(tightbvh.shapes.Sphere(0.1), pose, tightbvh.Model(a), None)
"""
import sys as _sys

from ._tightbvh import (
    CONTACT_KINDS,
    Ball,
    Box,
    ContactData,
    Distance,
    DistanceData,
    Dop,
    Ellipsoid,
    Mesh,
    Model,
    Result,
    Scene,
    ShapeDistance,
    ShapeResult,
    Tree,
    TreeCheck,
    __version__,
    as_mesh,
    build,
    collide,
    collide_batch,
    collide_brute_force,
    collide_shape,
    distance,
    distance_batch,
    distance_brute_force,
    distance_shape,
    fit,
    fit_methods,
    fitter_names,
    load_mesh,
    refit,
    shapes,
    split_names,
)

# `from tightbvh.shapes import Sphere` as for a package module.
_sys.modules[__name__ + ".shapes"] = shapes

__all__ = [
    "CONTACT_KINDS",
    "Ball",
    "Box",
    "ContactData",
    "Distance",
    "DistanceData",
    "Dop",
    "Ellipsoid",
    "Mesh",
    "Model",
    "Result",
    "Scene",
    "ShapeDistance",
    "ShapeResult",
    "Tree",
    "TreeCheck",
    "as_mesh",
    "build",
    "collide",
    "collide_batch",
    "collide_brute_force",
    "collide_shape",
    "distance",
    "distance_batch",
    "distance_brute_force",
    "distance_shape",
    "fit",
    "fit_methods",
    "fitter_names",
    "load_mesh",
    "refit",
    "shapes",
    "split_names",
]
