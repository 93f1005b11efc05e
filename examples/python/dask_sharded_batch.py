"""A sweep of many poses (a grasp or motion-planning dataset) sharded over a Dask cluster: each
shard is one collide_batch call on a worker, and the gathered answers equal one in-process
collide_batch over all the poses. Exits 1 on any difference.

Usage: dask_sharded_batch.py [--poses N] [--shards K] [--scheduler ADDRESS]
Without --scheduler it starts a local cluster of two worker processes; with a scheduler address
(tcp://host:8786) it uses that cluster, whose workers must be able to `import tightbvh`."""
import argparse
import logging
import os
import pathlib
import sys

import numpy as np
import tightbvh
from distributed import Client, LocalCluster


def random_poses(count, center, spread, seed=1):
    """(count, 4, 4) poses: uniform random rotations (normalized Gaussian quaternions), and
    translations within `spread` of `center`, so that the sweep has both hits and misses."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(4, count))
    w, x, y, z = q / np.linalg.norm(q, axis=0)
    rotations = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                          [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                          [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    poses = np.tile(np.eye(4), (count, 1, 1))
    poses[:, :3, :3] = np.moveaxis(rotations, -1, 0)
    poses[:, :3, 3] = center + rng.uniform(-spread, spread, size=(count, 3))
    return poses


def collide_shard(tree_a, tree_b, poses):
    """Runs on a worker: one batch call per shard. The trees come with their meshes (None below:
    each tree's own); threads=1: Dask already runs one task per worker thread, so the parallelism
    comes from the shards."""
    return tightbvh.collide_batch(tree_a, None, None, tree_b, None, poses, all_pairs=True, threads=1)


def main():
    parser = argparse.ArgumentParser(description="collide_batch over shards of a pose sweep on a Dask cluster")
    parser.add_argument("--poses", type=int, default=20_000)
    parser.add_argument("--shards", type=int, default=40)
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (default: a local cluster)")
    args = parser.parse_args()

    meshes = pathlib.Path(__file__).resolve().parents[2] / "meshes"
    elephant, knot = tightbvh.load_mesh(meshes / "elephant.off"), tightbvh.load_mesh(meshes / "knot1.off")
    tree_a, tree_b = tightbvh.build(elephant, fitter="approx"), tightbvh.build(knot)
    low, high = elephant.vertices.min(axis=0), elephant.vertices.max(axis=0)
    poses = random_poses(args.poses, (low + high) / 2, high - low)

    if args.scheduler:
        cluster = None
        client = Client(args.scheduler)
    else:
        # Local worker processes start fresh interpreters: they find the tightbvh this script
        # imported (e.g. build/python) only through PYTHONPATH, which they inherit.
        package_root = str(pathlib.Path(tightbvh.__file__).resolve().parents[1])
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [package_root, os.environ.get("PYTHONPATH")]))
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        # The trees travel once to every worker (pickled through the tree format, meshes
        # included), not once per shard: each task gets a reference to the worker's copy.
        tree_a_remote, tree_b_remote = client.scatter([tree_a, tree_b], broadcast=True)
        shards = np.array_split(poses, args.shards)
        futures = [client.submit(collide_shard, tree_a_remote, tree_b_remote, shard, pure=False) for shard in shards]
        results = client.gather(futures)  # in the order of `futures`: pose order
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    hits = np.concatenate([hits for hits, _ in results])
    pair_counts = np.concatenate([counts for _, counts in results])

    # The same sweep in this process, in one call: the sharded answers must be identical.
    expected_hits, expected_counts = tightbvh.collide_batch(tree_a, None, None, tree_b, None, poses, all_pairs=True)
    differences = np.flatnonzero((hits != expected_hits) | (pair_counts != expected_counts))
    print(f"{len(poses)} poses in {len(shards)} shards: {int(hits.sum())} hits, "
          f"{int(pair_counts.sum())} touching pairs, {len(differences)} differences from one process")
    for i in differences[:10]:
        print(f"  pose {i}: cluster {hits[i]}/{pair_counts[i]}, in process {expected_hits[i]}/{expected_counts[i]}")
    return 1 if len(differences) else 0


if __name__ == "__main__":  # worker processes import this file: only the main process runs the sweep
    sys.exit(main())
