#!/usr/bin/env bash
# The README's install path, end to end: a venv over Debian's python3 (--system-site-packages, so
# NumPy comes from python3-numpy), `pip install --no-build-isolation ./python` (nothing downloaded:
# --no-index makes any download attempt an error), then the package imported from outside the
# repository and both examples run with it.
#   tests/python/pip_install.sh [CMAKE_BUILD_DIR]   (kept between runs: reinstalls are incremental)
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
export TIGHTBVH_PIP_BUILD_DIR=$(realpath -m "${1:-build-pip}")
venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
/usr/bin/python3 -m venv --system-site-packages "$venv"
"$venv/bin/pip" install --quiet --no-index --no-build-isolation ./python
cd "$venv"
"$venv/bin/python" - <<'PY'
import pathlib
import tightbvh
here = pathlib.Path(tightbvh.__file__).resolve()
assert "site-packages" in str(here), here  # the installed package, not the source tree
print("installed", tightbvh.__version__, "at", here.parent)
PY
"$venv/bin/python" "$root/examples/python/collide_two_meshes.py" | head -2
"$venv/bin/python" "$root/examples/python/fit_containers.py" "$root/meshes/knot1.off" | head -3
echo "pip_install: ok"
