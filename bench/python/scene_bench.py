"""Python's overhead on scene queries: a scene file (the format of include/tightbvh/scene_file.hpp)
loaded through tightbvh.Model and tightbvh.Scene and self-collided with in_collision_internal(),
against the same scene in C++ (tightbvh-bench --scene ... --engines tightbvh), alternating, repeated;
prints the medians and the ratio of Python's time per check (or frame) to C++'s.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/scene_bench.py \\
        [--scenes out/scenes/a-touching.json,...] [--exe build/bin/tightbvh-bench] \\
        [--rounds 3] [--min-seconds 0.3] [--json FILE]

Both sides time what tightbvh-bench --scene times, on one thread, in thread CPU time (which other
processes on a shared machine do not inflate): without frames, repeated self-collisions of the
unchanged scene (checks/s), after one untimed check; with frames, every frame's moves
(set_transforms with an (N, 4, 4) array, prepared before the timing) and the self-collision that
follows (frames/s). The Python time includes all a caller pays: the call, the GIL release and the
result (a bool, as trimesh's in_collision_internal()). The touching pairs are checked against the
C++ program's count (which it checks against brute force); the script exits with status 1 when
they differ. Python stdlib, NumPy and tightbvh.
"""
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
SCENES = ",".join(f"out/scenes/{n}.json" for n in ("a-touching", "b-apart", "c-chain", "d-many"))


def matrix(pose):
    """The 4x4 transform of a scene file's pose: 9 rotation numbers (row-major), then the translation."""
    m = np.eye(4)
    m[:3, :3] = np.array(pose[:9], dtype=np.float64).reshape(3, 3)
    m[:3, 3] = pose[9:12]
    return m


def load(path):
    """(scene, names, initial transforms, frames): each frame (names, (N, 4, 4) transforms)."""
    spec = json.loads(path.read_text())
    folder = path.parent
    models = {name: tightbvh.Model(folder / file) for name, file in spec["models"].items()}
    scene = tightbvh.Scene()
    names = [o["name"] for o in spec["objects"]]
    initial = np.stack([matrix(o["pose"]) for o in spec["objects"]])
    for o, transform in zip(spec["objects"], initial):
        scene.add_object(o["name"], models[o["model"]], transform)
    for a, b in spec.get("allowed", []):
        scene.allow(a, b)
    frames = []
    if "frames" in spec:
        text = (folder / spec["frames"]).read_text()
        for block in text.split("\n---\n"):
            rows = [line.split() for line in block.splitlines() if line.strip() and line.strip() != "---"]
            frames.append(([r[0] for r in rows], np.stack([matrix([float(v) for v in r[1:]]) for r in rows])))
    return scene, names, initial, frames


def touching(scene, names, initial, frames):
    """The touching pairs summed over the initial poses and every frame (as the C++ program counts)."""
    scene.set_transforms(names, initial)
    count = len(scene.in_collision_internal(return_names=True)[1])
    for moved, transforms in frames:
        scene.set_transforms(moved, transforms)
        count += len(scene.in_collision_internal(return_names=True)[1])
    return count


def python_rate(scene, names, initial, frames, min_seconds):
    """Checks/s or frames/s, as tightbvh-bench --scene's rate() for one repetition."""
    scene.set_transforms(names, initial)
    scene.in_collision_internal()  # brings the top-level tree up to date outside the timing
    if not frames:  # batches of doubling size between clock reads (a system call), as in C++
        count, batch, elapsed, start = 0, 1, 0.0, time.thread_time()
        while elapsed < min_seconds:
            for _ in range(batch):
                scene.in_collision_internal()
            count += batch
            batch *= 2
            elapsed = time.thread_time() - start
        return count / elapsed
    start = time.thread_time()
    for moved, transforms in frames:
        scene.set_transforms(moved, transforms)
        scene.in_collision_internal()
    return len(frames) / (time.thread_time() - start)


def cpp_run(args, scene_path, out):
    command = [args.exe, "--scene", str(scene_path), "--engines", "tightbvh", "--reps", "1",
               "--min-seconds", str(args.min_seconds), "--json", str(out)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    result = json.loads(out.read_text())
    row = next(r for r in result["rows"] if r["engine"] == "tightbvh")
    if row["mismatches"]:
        sys.exit(f"scene_bench: {scene_path}: the C++ scene differs from brute force")
    return row["rate"], row["pairs"], result


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", default=SCENES, help="comma-separated scene files")
    parser.add_argument("--exe", default=str(ROOT / "build" / "bin" / "tightbvh-bench"))
    parser.add_argument("--rounds", type=int, default=3, help="C++ then Python, this many times (medians)")
    parser.add_argument("--min-seconds", type=float, default=0.3, help="without frames: CPU seconds per repetition")
    parser.add_argument("--json", type=pathlib.Path, help="write the settings and rows to this file")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene_file in args.scenes.split(","):
            path = pathlib.Path(scene_file)
            loaded = load(path)
            scene, names, _, frames = loaded
            pairs = touching(*loaded)
            cpp, python = [], []
            for _ in range(args.rounds):
                rate, cpp_pairs, result = cpp_run(args, path, pathlib.Path(tmp) / "cpp.json")
                cpp.append(rate)
                python.append(python_rate(*loaded, args.min_seconds))
            if pairs != cpp_pairs:
                sys.exit(f"scene_bench: {path}: Python found {pairs} touching pairs, C++ {cpp_pairs}")
            row = {"scene": path.stem, "objects": len(scene), "models": scene.model_count, "frames": len(frames),
                   "unit": "frames/s" if frames else "checks/s", "pairs": pairs,
                   "cpp_rate": statistics.median(cpp), "python_rate": statistics.median(python),
                   "cpp_rates": cpp, "python_rates": python}
            row["ratio"] = row["cpp_rate"] / row["python_rate"]  # Python's time over C++'s
            rows.append(row)
            print(f"{path.stem}: {len(scene)} objects, {pairs} touching pairs; C++ {row['cpp_rate']:.4g} "
                  f"{row['unit']}, Python {row['python_rate']:.4g}: Python / C++ time {row['ratio']:.3f}",
                  flush=True)
    if args.json:
        args.json.write_text(json.dumps({"rounds": args.rounds, "min_seconds": args.min_seconds,
                                         "clock": "thread CPU", "threads": 1, "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
