#!/usr/bin/env python3
"""collide_batch on 1 thread and on 2: wall time of tightbvh-batch-bench per scenario and mode.

    bench/python/batch_threads.py BUILD_DIR WORK_DIR [--reps R]

Builds the shipped pair's default trees and writes 10,000 poses per scenario with tightbvh-bench
(--write-poses) into WORK_DIR, then runs tightbvh-batch-bench with --threads 1 and 2 and prints
the median wall time of the repetitions after 5 warm-up ones (the first batches of a process pay
page faults and cold caches), and the speed-up. overlap all_pairs (~10 s a batch) gets 3.
"""
import argparse
import json
import os
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build_dir")
    parser.add_argument("work_dir")
    parser.add_argument("--reps", type=int, default=21)
    args = parser.parse_args()
    bins = os.path.join(os.path.abspath(args.build_dir), "bin")
    work = os.path.abspath(args.work_dir)
    os.makedirs(work, exist_ok=True)
    meshes = {k: os.path.join(ROOT, "meshes", k + ".off") for k in ("elephant", "knot1")}
    trees = {k: os.path.join(work, k + ".tree") for k in meshes}
    for k in meshes:
        subprocess.run([os.path.join(bins, "tightbvh"), "build", meshes[k], "-o", trees[k]], check=True,
                       stdout=subprocess.DEVNULL)
    for scenario in ("near", "overlap", "separated"):
        poses = os.path.join(work, scenario + ".txt")
        if not os.path.exists(poses):
            subprocess.run([os.path.join(bins, "tightbvh-bench"), "--scenario", scenario, "--poses", "10000",
                            "--engines", "tightbvh-auto", "--modes", "first_hit", "--budget", "0.1",
                            "--write-poses", poses], check=True, stdout=subprocess.DEVNULL, cwd=ROOT)
        for all_pairs in (False, True):
            reps = 5 + (3 if scenario == "overlap" and all_pairs else args.reps)
            median = {}
            for threads in (1, 2):
                cmd = [os.path.join(bins, "tightbvh-batch-bench"), meshes["elephant"], trees["elephant"],
                       meshes["knot1"], trees["knot1"], poses, "--reps", str(reps), "--threads", str(threads)]
                out = subprocess.run(cmd + (["--all-pairs"] if all_pairs else []), check=True, capture_output=True,
                                     text=True).stdout
                median[threads] = statistics.median(json.loads(out)["wall_seconds"][5:])
            mode = "all_pairs" if all_pairs else "first_hit"
            print(f"| {scenario} | {mode} | {median[1] * 1e3:.1f} | {median[2] * 1e3:.1f} | "
                  f"{median[1] / median[2]:.2f} |", flush=True)


if __name__ == "__main__":
    main()
