"""examples/python/dask_sharded_batch.py on a local Dask cluster of two worker processes: the
sharded collide_batch answers equal one in-process call (the example exits 1 otherwise)."""
import os
import pathlib
import subprocess
import sys

import pytest
import tightbvh
from conftest import SOURCE_DIR

try:
    import distributed  # noqa: F401  (Debian's python3-distributed, installed by scripts/setup)
except ImportError as error:
    pytest.skip(f"Dask's distributed cannot be imported ({error}); scripts/setup installs python3-distributed",
                allow_module_level=True)


def test_sharded_sweep_on_a_local_cluster_equals_one_process():
    # The workers are new interpreters: they import the module of this build through PYTHONPATH.
    package_root = str(pathlib.Path(tightbvh.__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [package_root, os.environ.get("PYTHONPATH")])))
    example = SOURCE_DIR / "examples" / "python" / "dask_sharded_batch.py"
    # The timeout only keeps a hung cluster from hanging the suite; it is no measurement.
    out = subprocess.run([sys.executable, str(example), "--poses", "2000", "--shards", "8"], env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "2000 poses in 8 shards" in out.stdout and "0 differences from one process" in out.stdout, out.stdout
    hits = int(out.stdout.split(" hits")[0].rsplit(" ", 1)[1])
    assert 0 < hits < 2000  # the sweep has hits and misses: the comparison means something
