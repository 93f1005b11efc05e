"""pip install --no-build-isolation ./python

Builds the extension tightbvh._tightbvh with the project's own CMake (the library and python/
only, nothing downloaded: Debian's pybind11-dev, python3-numpy, python3-setuptools) and installs
the package. TIGHTBVH_PIP_BUILD_DIR keeps the CMake build folder between installs (default: a
temporary folder of setuptools); TIGHTBVH_JOBS sets the parallel jobs (default: all cores)."""
import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent.parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(tightbvh VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = pathlib.Path(os.environ.get("TIGHTBVH_PIP_BUILD_DIR") or self.build_temp).resolve()
        jobs = os.environ.get("TIGHTBVH_JOBS") or str(os.cpu_count() or 1)
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
            "-DTIGHTBVH_PYTHON=ON", "-DTIGHTBVH_BUILD_TESTS=OFF", "-DTIGHTBVH_BUILD_BENCH=OFF",
            "-DTIGHTBVH_BUILD_APPS=OFF", "-DTIGHTBVH_BUILD_EXAMPLES=OFF",
            f"-DPython_EXECUTABLE={sys.executable}",
        ]
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "tightbvh_python", "-j", jobs], check=True)
        built = next((build_dir / "python" / "tightbvh").glob("_tightbvh*.so"))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    name="tightbvh",
    version=project_version(),
    description="Bounding-volume hierarchies of tight oriented boxes over triangle meshes, for collision detection",
    packages=["tightbvh"],
    ext_modules=[CMakeExtension("tightbvh._tightbvh")],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.8",
    install_requires=["numpy"],
    zip_safe=False,
)
