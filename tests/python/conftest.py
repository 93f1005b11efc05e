"""Shared fixtures of the pytest suite: the module from the build (PYTHONPATH=build/python, set by
ctest's python_tests), the CLI it is compared with (TIGHTBVH_CLI) and the shipped meshes."""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("TIGHTBVH_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
MESHES = SOURCE_DIR / "meshes"


def cli_path():
    path = os.environ.get("TIGHTBVH_CLI", str(SOURCE_DIR / "build" / "bin" / "tightbvh"))
    return path if os.path.exists(path) else None


@pytest.fixture(scope="session")
def cli():
    """Runs `tightbvh ARGS... --json` and returns the parsed output."""
    path = cli_path()
    if path is None:
        pytest.skip("the tightbvh CLI is not built (set TIGHTBVH_CLI)")

    def run(*args):
        out = subprocess.run([path, *map(str, args), "--json"], check=True, capture_output=True, text=True)
        return json.loads(out.stdout)

    run.path = path
    return run


@pytest.fixture(scope="session")
def elephant():
    import tightbvh

    return tightbvh.load_mesh(MESHES / "elephant.off")


@pytest.fixture(scope="session")
def knot():
    import tightbvh

    return tightbvh.load_mesh(MESHES / "knot1.off")


def tetrahedron():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)
    return vertices, faces


def rotation(axis, angle):
    """Rodrigues' rotation matrix."""
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def pose_matrix(r, t):
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = t
    return m


def pose_text(m):
    """The CLI's --pose text: row-major rotation, then translation, printed to round-trip."""
    return " ".join(repr(float(x)) for x in [*m[:3, :3].ravel(), *m[:3, 3]])
