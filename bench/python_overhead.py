"""The Python side of the overhead measure (bench/python_overhead.sh): as bench_python.

usage: PYTHONPATH=python python3 bench/python_overhead.py render|rays|rays+normals N [SIZE]
(rays+normals: Scene.intersect with its normals, which the C stream API does not give)"""
import sys

import numpy as np

import rastray

mode, n = sys.argv[1], int(sys.argv[2])
size = int(sys.argv[3]) if len(sys.argv) > 3 else 1024
with rastray.Scene.from_file("demo", threads=1) as scene:
    cam = scene.frame_camera((size, size))
    if mode == "render":
        for _ in range(n):
            scene.render(cam, size=(size, size), method="3dr-bin", aovs=("depth", "id", "normal", "mesh"), threads=1)
    else:
        org, dirs = cam.rays((size, size))
        rays = np.concatenate([org, dirs], axis=-1).reshape(-1, 6)
        for _ in range(n):
            scene.intersect(rays, threads=1, normals=mode == "rays+normals")
