"""Point queries against Open3D's RaycastingScene (Debian's python3-open3d 0.16, Embree inside):
closest points, signed distance and inside/outside for many points, the same thread count for both.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/points_bench.py \\
        [--points 1000000] [--threads 2] [--reps 3] [--meshes meshes/fandisk.off,...] [--json FILE]

For each closed mesh (the shipped ones and a few corpus ones; open meshes are skipped, since
neither engine's sign means anything there) and four kinds of points: uniform in the bounding box;
near the surface (a surface point moved by a normal deviate of 1% of the diagonal); on the surface
(the mesh's own vertices, cycled: exactly on it); on an axis-aligned grid over the bounding box
(where one ray's parity meets edges and vertices). Timed: tightbvh's Model.closest_points,
signed_distance and contains, against Open3D's compute_closest_points, compute_signed_distance
and compute_occupancy, median wall-clock time of --reps runs each (points/s).

Answers: tightbvh's contains is the exact reference for the side (ray parity with exact
predicates); a sign counts as wrong when an engine puts a point that is strictly inside or outside
on the other side (points on the surface are left out of the count). Open3D computes in single
precision: its distances are compared with ours to report the largest difference relative to the
mesh's diagonal. Before timing, Open3D is checked on a unit cube at the origin and far from it (a
point inside must come out inside); a failure is reported and its timings are kept but flagged.
"""
import argparse
import json
import pathlib
import statistics
import sys
import time

import numpy as np
import open3d as o3d
import tightbvh

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_MESHES = ["meshes/fandisk.off", "meshes/elephant.off", "meshes/knot1.off",
                  "meshes/corpus/cgal/bull.off", "meshes/corpus/cgal/mushroom.off"]
KINDS = ["uniform", "near", "surface", "grid"]


def open3d_scene(vertices, faces, threads):
    scene = o3d.t.geometry.RaycastingScene(nthreads=threads)
    scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)), o3d.core.Tensor(faces.astype(np.uint32)))
    return scene


def open3d_sanity(threads):
    """Problems Open3D shows on a unit cube (at the origin and at 1e4): a list of strings."""
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    problems = []
    for offset in (0.0, 1e4):
        try:
            scene = open3d_scene(corners + offset, faces, threads)
            # inside at a generic point (no ray from it meets an edge), then outside
            q = o3d.core.Tensor(np.array([[0.3, 0.6, 0.45], [1.5, 0.5, 0.5]], dtype=np.float32) + np.float32(offset))
            occupancy = scene.compute_occupancy(q, nthreads=threads).numpy()
            signed = scene.compute_signed_distance(q, nthreads=threads).numpy()
            if not (occupancy[0] > 0 and occupancy[1] == 0 and signed[0] < 0 < signed[1]):
                problems.append(f"cube at {offset:g}: occupancy {occupancy.tolist()}, signed {signed.tolist()}")
        except Exception as e:  # noqa: BLE001 - any failure of the peer is reported, not raised
            problems.append(f"cube at {offset:g}: {type(e).__name__}: {e}")
    return problems


def make_points(vertices, faces, kind, count, rng):
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    diagonal = np.linalg.norm(hi - lo)
    if kind == "uniform":
        return lo + rng.random((count, 3)) * (hi - lo)
    if kind == "surface":
        return vertices[np.arange(count) % len(vertices)]
    if kind == "grid":
        side = int(np.ceil(count ** (1 / 3)))
        axes = [np.linspace(lo[k], hi[k], side) for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        return grid[:count]
    # near: random points on random triangles, moved by a normal deviate of 1% of the diagonal
    tri = faces[rng.integers(0, len(faces), count)]
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    a, b, c = vertices[tri[:, 0]], vertices[tri[:, 1]], vertices[tri[:, 2]]
    surface = a + u[:, None] * (b - a) + v[:, None] * (c - a)
    return surface + rng.normal(scale=0.01 * diagonal / np.sqrt(3), size=(count, 3))


def timed(fn, reps):
    seconds, result = [], None
    for _ in range(reps):
        start = time.perf_counter()
        result = fn()
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds), result


def run_mesh(path, args, rng):
    mesh = tightbvh.load_mesh(str(path))
    vertices, faces = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    model = tightbvh.Model(mesh)
    try:
        model.contains(vertices[:1], threads=1)
    except ValueError as e:
        print(f"points_bench: skipped {path.name}: {e}", file=sys.stderr)
        return []
    scene = open3d_scene(vertices, faces, args.threads)
    diagonal = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    rows = []
    for kind in KINDS:
        points = np.ascontiguousarray(make_points(vertices, faces, kind, args.points, rng))
        n = len(points)
        q = o3d.core.Tensor(points.astype(np.float32))
        inside, on_surface = model.contains(points, threads=args.threads, return_on_surface=True)
        decided = ~on_surface
        t_closest, (_, distance, _) = timed(lambda: model.closest_points(points, threads=args.threads), args.reps)
        t_signed, signed = timed(lambda: model.signed_distance(points, threads=args.threads), args.reps)
        t_contains, _ = timed(lambda: model.contains(points, threads=args.threads), args.reps)
        o_closest, o_result = timed(lambda: scene.compute_closest_points(q, nthreads=args.threads), args.reps)
        o_signed, o_sd = timed(lambda: scene.compute_signed_distance(q, nthreads=args.threads), args.reps)
        o_occupancy, o_occ = timed(lambda: scene.compute_occupancy(q, nthreads=args.threads), args.reps)
        o_points = o_result["points"].numpy().astype(np.float64)
        o_distance = np.linalg.norm(o_points - points, axis=1)
        o_sd = o_sd.numpy().astype(np.float64)
        o_inside = o_occ.numpy() > 0
        rows.append({
            "mesh": path.name, "triangles": len(faces), "kind": kind, "points": n,
            "on_surface": int(on_surface.sum()), "inside": int(inside.sum()),
            "tightbvh": {"closest_points_per_s": n / t_closest, "signed_distance_per_s": n / t_signed,
                         "contains_per_s": n / t_contains,
                         "wrong_signs": int(((signed < 0) != inside)[decided].sum() + (signed[decided] == 0).sum()),
                         "wrong_contains": 0},
            "open3d": {"closest_points_per_s": n / o_closest, "signed_distance_per_s": n / o_signed,
                       "contains_per_s": n / o_occupancy,
                       "wrong_signs": int(((o_sd < 0) != inside)[decided].sum()),
                       "wrong_contains": int((o_inside != inside)[decided].sum()),
                       "max_distance_difference": float(np.abs(o_distance - distance).max() / diagonal)},
        })
        r = rows[-1]
        print(f"{path.name:>14} {kind:>8}: closest {r['tightbvh']['closest_points_per_s'] / 1e3:8.0f} vs "
              f"{r['open3d']['closest_points_per_s'] / 1e3:8.0f} k/s, signed {r['tightbvh']['signed_distance_per_s'] / 1e3:8.0f} "
              f"vs {r['open3d']['signed_distance_per_s'] / 1e3:8.0f} k/s, wrong signs {r['tightbvh']['wrong_signs']} vs "
              f"{r['open3d']['wrong_signs']}", flush=True)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--meshes", default=",".join(DEFAULT_MESHES))
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json")
    args = parser.parse_args()
    if args.points < 1 or args.threads < 1 or args.reps < 1:
        parser.error("--points, --threads and --reps must be >= 1")
    rng = np.random.default_rng(args.seed)
    problems = open3d_sanity(args.threads)
    for p in problems:
        print(f"points_bench: Open3D: {p}", file=sys.stderr)
    rows = []
    for name in args.meshes.split(","):
        path = ROOT / name
        if not path.exists():
            print(f"points_bench: skipped {name}: not found (meshes/fetch-corpus for the corpus)", file=sys.stderr)
            continue
        rows += run_mesh(path, args, rng)
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(
            {"points": args.points, "threads": args.threads, "reps": args.reps, "clock": "wall",
             "open3d_version": o3d.__version__, "open3d_problems": problems, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
