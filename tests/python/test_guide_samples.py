"""The scripts in examples/python/guide (quoted by docs/user-guide.md) run and print what they promise."""
import os
import subprocess
import sys

from conftest import SOURCE_DIR

GUIDE = SOURCE_DIR / "examples" / "python" / "guide"


def run(script):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    out = subprocess.run([sys.executable, GUIDE / script], check=True, capture_output=True, text=True, env=env)
    return out.stdout.splitlines()


def test_poses_and_batches():
    lines = run("poses_and_batches.py")
    assert lines[0].startswith("touching pairs: ") and lines[0].endswith("(the same with (R, t): True)")
    assert int(lines[0].split()[2]) > 0
    assert lines[1].startswith("intersection curve: ") and int(lines[1].split()[2]) > 0
    hit, _, total = lines[2].split()[:3]
    assert 0 < int(hit) < int(total) == 64
    assert lines[3].startswith("distance: ")
    assert lines[4].startswith("loaded ") and lines[4].endswith("valid: True")
    assert lines[5].startswith("ValueError: ") and "pose" in lines[5]
    assert len(lines) == 6
