"""The scripts in examples/python run and print what they promise."""
import os
import subprocess
import sys

import tightbvh
from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"


def run(script, *args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    out = subprocess.run([sys.executable, EXAMPLES / script, *args], check=True, capture_output=True, text=True, env=env)
    return out.stdout


def test_collide_two_meshes_prints_the_pairs():
    out = run("collide_two_meshes.py")
    lines = out.splitlines()
    assert lines[0].startswith("hit: ") and "touching triangle pairs" in lines[0]
    assert len(lines) == 12 and all(line.startswith("  triangle ") for line in lines[1:11])
    assert lines[11].startswith("at x = 1.5: distance ") and float(lines[11].split()[5]) > 0


def test_fit_containers_prints_every_volume():
    out = run("fit_containers.py", str(SOURCE_DIR / "meshes" / "knot1.off"))
    rows = out.splitlines()[1:]
    assert [r.split()[0] for r in rows] == tightbvh.fit_methods()
    exact_row = next(r for r in rows if r.startswith("exact "))
    assert exact_row.split()[2] == "1.0000"


# The scripts below check their own answers (a fresh build, the brute-force reference, single
# queries) and exit non-zero when one is wrong: check=True in run() fails the test then.
def test_refit_deforming_mesh_agrees_with_fresh_builds():
    lines = run("refit_deforming_mesh.py").splitlines()
    assert [line.split(":")[0] for line in lines[:-1]] == [f"frame {i}" for i in range(8)]
    assert lines[-1] == "refitted tree agrees with fresh builds on all 8 frames"


def test_distance_closest_points_agrees_with_brute_force():
    lines = run("distance_closest_points.py").splitlines()
    assert lines[0].startswith("distance ") and float(lines[0].split()[1]) > 0
    assert lines[-1].startswith("brute force: ") and lines[-1].endswith(": agrees")


def test_collide_many_poses_equals_single_queries():
    last = run("collide_many_poses.py").splitlines()[-1]
    assert last.startswith("64 poses on 2 threads: ") and last.endswith("equal to 64 single queries")
    touching, apart = int(last.split()[5]), int(last.split()[7])
    assert touching > 0 and apart > 0 and touching + apart == 64


def test_point_queries_agree_with_brute_force():
    lines = run("point_queries.py").splitlines()
    assert lines[0].startswith("2000 points: ") and int(lines[0].split()[2]) > 0
    assert lines[-1] == "brute force and signs: agree"


def test_shapes_against_a_mesh_agree_with_the_point_queries():
    lines = run("shapes_against_a_mesh.py").splitlines()
    assert lines[0].startswith("capsule: ") and int(lines[0].split()[1]) > 0
    assert lines[1].startswith("sphere: distance ") and lines[2].startswith("box at the origin: distance ")
    assert lines[-1] == "checks: agree"
