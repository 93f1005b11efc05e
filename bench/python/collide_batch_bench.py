"""Python's overhead on collide_batch: the same 1,000 poses, trees and meshes through
tightbvh.collide_batch (Python) and through tightbvh-batch-bench (C++, collide_batch directly),
alternating, repeated; prints the medians and the ratio Python / C++.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/collide_batch_bench.py \\
        [--exe build/bin/tightbvh-batch-bench] [--poses 1000] [--reps 5] [--rounds 3] [--threads 1] [--json FILE]

With --threads 1 (default) both sides run on the calling thread and the ratio is of thread CPU
time, which other processes on a shared machine do not inflate; with more threads it is of
wall-clock time. The Python time includes everything a caller pays: converting and checking the
(N, 4, 4) pose array, the call, and building the result arrays. --json FILE also writes the
settings and the rows (medians, ratio, and every timed batch of both sides) to FILE."""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import tightbvh

ROOT = pathlib.Path(__file__).resolve().parents[2]


def random_poses(mesh_a, mesh_b, count, seed):
    """B's center placed at random within A's bounding radius (overlapping, grazing and apart),
    uniformly random rotations."""
    rng = np.random.default_rng(seed)
    center_a = mesh_a.vertices.mean(axis=0)
    center_b = mesh_b.vertices.mean(axis=0)
    radius = np.linalg.norm(mesh_a.vertices - center_a, axis=1).max()
    poses = np.zeros((count, 4, 4))
    for i in range(count):
        q = rng.normal(size=4)
        w, x, y, z = q / np.linalg.norm(q)
        r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        where = center_a + rng.uniform(-1.2, 1.2, size=3) * radius
        poses[i, :3, :3] = r
        poses[i, :3, 3] = where - r @ center_b
        poses[i, 3, 3] = 1.0
    return poses


def time_python(args, tree_a, a, tree_b, b, poses, all_pairs):
    clock = time.thread_time if args.threads == 1 else time.perf_counter
    seconds = []
    for _ in range(args.reps):
        start = clock()
        hits, counts = tightbvh.collide_batch(tree_a, a, None, tree_b, b, poses, all_pairs, args.threads)
        seconds.append(clock() - start)
    return seconds, int(hits.sum()), int(counts.sum())


def time_cpp(args, files, all_pairs):
    command = [args.exe, *files, "--reps", str(args.reps), "--threads", str(args.threads)]
    out = json.loads(subprocess.run(command + (["--all-pairs"] if all_pairs else []), check=True,
                                    capture_output=True, text=True).stdout)
    return out["cpu_seconds" if args.threads == 1 else "wall_seconds"], out["hits"], out["pairs"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--exe", default=str(ROOT / "build/bin/tightbvh-batch-bench"))
    parser.add_argument("--mesh-a", default=str(ROOT / "meshes/elephant.off"))
    parser.add_argument("--mesh-b", default=str(ROOT / "meshes/knot1.off"))
    parser.add_argument("--fitter", default="auto")
    parser.add_argument("--poses", type=int, default=1000)
    parser.add_argument("--reps", type=int, default=5, help="batches per round and side")
    parser.add_argument("--rounds", type=int, default=3, help="C++ then Python, this many times")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", help="also write the results to this JSON file")
    args = parser.parse_args()

    a, b = tightbvh.load_mesh(args.mesh_a), tightbvh.load_mesh(args.mesh_b)
    tree_a, tree_b = tightbvh.build(a, fitter=args.fitter), tightbvh.build(b, fitter=args.fitter)
    poses = random_poses(a, b, args.poses, args.seed)
    print(f"{pathlib.Path(args.mesh_a).name} vs {pathlib.Path(args.mesh_b).name}, fitter {args.fitter}, "
          f"{args.poses} poses, {args.threads} thread(s), {args.rounds} rounds x {args.reps} batches per side; "
          f"{'thread CPU' if args.threads == 1 else 'wall-clock'} seconds per batch (median)")
    print(f"{'mode':<10} {'hits':>5} {'pairs':>8} {'C++ s':>10} {'Python s':>10} {'Python/C++':>10}")
    with tempfile.TemporaryDirectory() as tmp:
        files = [args.mesh_a, f"{tmp}/a.tree", args.mesh_b, f"{tmp}/b.tree", f"{tmp}/poses.txt"]
        tree_a.save(files[1])
        tree_b.save(files[3])
        with open(files[4], "w") as out:
            for m in poses:  # repr round-trips: the C++ side reads the same doubles
                out.write(" ".join(repr(float(x)) for x in [*m[:3, :3].ravel(), *m[:3, 3]]) + "\n")
        rows = []
        for all_pairs in (False, True):
            cpp, py = [], []
            for _ in range(args.rounds):
                seconds, cpp_hits, cpp_pairs = time_cpp(args, files, all_pairs)
                cpp += seconds
                seconds, py_hits, py_pairs = time_python(args, tree_a, a, tree_b, b, poses, all_pairs)
                py += seconds
                if (py_hits, py_pairs) != (cpp_hits, cpp_pairs):
                    sys.exit(f"answers differ: C++ {cpp_hits} hits {cpp_pairs} pairs, Python {py_hits} {py_pairs}")
            mode = "all_pairs" if all_pairs else "first_hit"
            ratio = statistics.median(py) / statistics.median(cpp)
            rows.append({"mode": mode, "hits": py_hits, "pairs": py_pairs, "cpp_seconds": statistics.median(cpp),
                         "python_seconds": statistics.median(py), "ratio": ratio,
                         "cpp_samples": cpp, "python_samples": py})
            print(f"{mode:<10} {py_hits:>5} {py_pairs:>8} {statistics.median(cpp):10.5f} "
                  f"{statistics.median(py):10.5f} {ratio:10.3f}")
    if args.json:
        settings = {k: getattr(args, k) for k in ("mesh_a", "mesh_b", "fitter", "poses", "reps", "rounds", "threads",
                                                  "seed")}
        settings["mesh_a"] = pathlib.Path(args.mesh_a).name
        settings["mesh_b"] = pathlib.Path(args.mesh_b).name
        settings["clock"] = "thread CPU" if args.threads == 1 else "wall-clock"
        with open(args.json, "w") as out:
            json.dump({**settings, "rows": rows}, out, indent=2)
            out.write("\n")
    return rows


if __name__ == "__main__":
    main()
