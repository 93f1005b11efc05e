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
