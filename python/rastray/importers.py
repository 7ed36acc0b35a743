"""Cameras of reconstruction tools as rastray cameras.

colmap_cameras(dir): COLMAP's text model (cameras.txt, images.txt). COLMAP puts the
centre of the top-left pixel at (0.5, 0.5), OpenCV at (0, 0): cx, cy lose 0.5.
Camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV and
OPENCV_FISHEYE (the others have no OpenCV equivalent and are refused).

nerf_cameras(path): a NeRF / instant-ngp transforms.json: camera_angle_x (or fl_x,
fl_y), optional cx, cy (default w/2, h/2, pixel centres at integers as NeRF's rays),
k1, k2, p1, p2 and per frame a camera-to-world transform_matrix in OpenGL's axes
(x right, y up, z back).

Both return a list of (name, Camera) whose size is the image's (w, h).
"""
import json
import os

import numpy as np

from . import Camera

_COLMAP = {  # model: parameter names after fx, fy, cx, cy
    "SIMPLE_PINHOLE": ("f", "cx", "cy"), "PINHOLE": ("fx", "fy", "cx", "cy"),
    "SIMPLE_RADIAL": ("f", "cx", "cy", "k1"), "RADIAL": ("f", "cx", "cy", "k1", "k2"),
    "OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"),
    "FULL_OPENCV": ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
    "OPENCV_FISHEYE": ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"),
}


def _lines(path):
    with open(path, encoding="utf-8") as f:
        return [l.strip() for l in f if l.strip() and not l.lstrip().startswith("#")]


def _quat_to_R(qw, qx, qy, qz):
    q = np.array([qw, qx, qy, qz], dtype=np.float64)
    n = np.linalg.norm(q)
    if not n > 0:
        raise ValueError("a zero quaternion")
    w, x, y, z = q / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def colmap_cameras(directory):
    """The images of a COLMAP text model as (name, Camera), in images.txt's order."""
    intr = {}
    for l in _lines(os.path.join(directory, "cameras.txt")):
        w = l.split()
        model, p = w[1], [float(x) for x in w[4:]]
        if model not in _COLMAP:
            raise ValueError("COLMAP camera model %s has no OpenCV equivalent (expected %s)"
                             % (model, ", ".join(_COLMAP)))
        names = _COLMAP[model]
        if len(p) != len(names):
            raise ValueError("COLMAP camera %s: %s takes %d parameters, not %d" % (w[0], model, len(names), len(p)))
        v = dict(zip(names, p))
        fx, fy = v.get("fx", v.get("f")), v.get("fy", v.get("f"))
        dist = [v.get(k, 0.0) for k in (("k1", "k2", "k3", "k4") if model == "OPENCV_FISHEYE" else
                                         ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"))]
        K = np.array([[fx, 0, v["cx"] - 0.5], [0, fy, v["cy"] - 0.5], [0, 0, 1]])
        intr[w[0]] = (K, dist, model == "OPENCV_FISHEYE", (int(w[2]), int(w[3])))
    out = []
    lines = _lines(os.path.join(directory, "images.txt"))
    for l in lines:
        w = l.split()
        # an image line has 10 fields, its 2D points line a multiple of 3; an empty
        # points line was dropped with the blanks
        if len(w) != 10 or w[8] not in intr:
            continue
        K, dist, fish, size = intr[w[8]]
        R = _quat_to_R(*(float(x) for x in w[1:5]))
        t = np.array([float(x) for x in w[5:8]])
        out.append((w[9], Camera.opencv(K, dist, R, t, size=size, fisheye=fish)))
    return out


def nerf_cameras(path):
    """The frames of a NeRF / instant-ngp transforms.json as (file_path, Camera)."""
    with open(path, encoding="utf-8") as f:
        meta = json.load(f)
    out = []
    for frame in meta.get("frames", []):
        m = dict(meta, **frame)  # instant-ngp allows per-frame intrinsics
        w, h = int(m["w"]), int(m["h"])
        fx = m.get("fl_x") or 0.5 * w / np.tan(0.5 * m["camera_angle_x"])
        fy = m.get("fl_y") or (0.5 * h / np.tan(0.5 * m["camera_angle_y"]) if "camera_angle_y" in m else fx)
        K = np.array([[fx, 0, m.get("cx", w / 2)], [0, fy, m.get("cy", h / 2)], [0, 0, 1]])
        dist = [m.get(k, 0.0) for k in ("k1", "k2", "p1", "p2")]
        c2w = np.asarray(m["transform_matrix"], dtype=np.float64)
        if c2w.shape != (4, 4):
            raise ValueError("transform_matrix must be 4x4")
        Rc = c2w[:3, :3] @ np.diag([1.0, -1.0, -1.0])  # OpenGL's camera axes to OpenCV's
        R = Rc.T
        t = -R @ c2w[:3, 3]
        out.append((frame.get("file_path", str(len(out))), Camera.opencv(K, dist, R, t, size=(w, h))))
    return out
