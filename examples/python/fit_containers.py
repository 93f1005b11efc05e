"""Fit every box method and container to one mesh and print the volumes, relative to the minimum
box (the Python twin of examples/fit_a_box.cpp and `tightbvh fit MESH --method all`).
Usage: fit_containers.py [MESH]"""
import pathlib
import sys
import time

import tightbvh

mesh_path = sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[2] / "meshes/knot1.off"
mesh = tightbvh.load_mesh(mesh_path)

fitted, seconds = {}, {}
for method in tightbvh.fit_methods():  # box methods (Box), then ball, ellipsoid, k-DOPs
    start = time.perf_counter()
    fitted[method] = tightbvh.fit(mesh, method)
    seconds[method] = time.perf_counter() - start

exact = fitted["exact"].volume  # the minimum-volume box
print(f"{'method':<12} {'volume':>14} {'vs exact':>9} {'seconds':>9}")
for method, container in fitted.items():
    print(f"{method:<12} {container.volume:14.8g} {container.volume / exact:9.4f} {seconds[method]:9.4f}")
