#!/usr/bin/env python3
"""Renders a depth / normal / mesh-id dataset of a scene from OpenCV cameras on a
circle around it, with lens distortion rendered directly (no undistort-and-resample).

usage: make_dataset.py [SCENE] [--views N] [--size WxH] [--out DIR] [--fisheye]

Writes per view NNNN (the conventions of BlenderProc / BOP-style datasets):
  NNNN_depth.npy   float32 metres along the optical axis (z-depth), 0 where nothing is hit
  NNNN_depth.png   uint16 millimetres, 0 where nothing is hit
  NNNN_normal.png  world normals, (n + 1) / 2 as 8-bit RGB
  NNNN_mesh.png    uint16 mesh id + 1, 0 where nothing is hit (instance mask)
and cameras.json: image size, K, distortion and per view R, t (world to camera,
x right, y down, z forward) -- everything cv2.projectPoints needs.
"""
import argparse
import json
import os

import cv2
import numpy as np

import rastray


def look_at(eye, target, up=(0, 1, 0)):
    """OpenCV's R, t for a camera at eye looking at target (y down in the image)."""
    z = np.asarray(target, float) - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.stack([x, y, z])
    return R, -R @ eye


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("scene", nargs="?", default="demo", help="a mesh file or a built-in scene (default demo)")
    ap.add_argument("--views", type=int, default=4)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--out", default="dataset")
    ap.add_argument("--fisheye", action="store_true", help="OpenCV's fisheye model instead of Brown-Conrady")
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    os.makedirs(a.out, exist_ok=True)
    f = 0.45 * w if a.fisheye else 0.9 * w
    K = np.array([[f, 0, (w - 1) / 2], [0, f, (h - 1) / 2], [0, 0, 1]])
    dist = np.array([0.02, -0.01, 0.002, 0.0]) if a.fisheye else np.array([-0.12, 0.03, 0.0005, -0.0005, 0.0])
    meta = {"width": w, "height": h, "K": K.tolist(), "dist": dist.tolist(),
            "model": "opencv-fisheye" if a.fisheye else "opencv", "views": []}
    with rastray.Scene.from_file(a.scene) as scene:
        lo, hi = scene.info["bounds"]
        centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
        for i in range(a.views):
            angle = 2 * np.pi * i / a.views
            eye = centre + radius * np.array([np.sin(angle), 0.5, np.cos(angle)]) * (0.6 if a.fisheye else 1.0)
            R, t = look_at(eye, centre)
            cam = rastray.Camera.opencv(K, dist, R, t, size=(w, h), fisheye=a.fisheye)
            out = scene.render(cam, aovs=("z-depth", "normal", "mesh"))
            hit = out["mesh"] != rastray.MISS
            depth = np.where(hit, out["z-depth"], 0).astype(np.float32)
            stem = os.path.join(a.out, "%04d" % i)
            np.save(stem + "_depth.npy", depth)
            cv2.imwrite(stem + "_depth.png", np.clip(np.round(depth * 1000), 0, 65535).astype(np.uint16))
            normal = np.where(hit[..., None], (out["normal"] + 1) * 0.5 * 255, 0)
            cv2.imwrite(stem + "_normal.png", np.round(normal).astype(np.uint8)[..., ::-1])  # OpenCV writes BGR
            cv2.imwrite(stem + "_mesh.png", np.where(hit, out["mesh"] + 1, 0).astype(np.uint16))
            meta["views"].append({"file": "%04d" % i, "R": R.tolist(), "t": t.tolist()})
            print("%s: %d of %d pixels hit, depth %.3f..%.3f m" % (stem, hit.sum(), hit.size,
                                                                   depth[hit].min() if hit.any() else 0,
                                                                   depth[hit].max() if hit.any() else 0))
    with open(os.path.join(a.out, "cameras.json"), "w") as fp:
        json.dump(meta, fp, indent=1)


if __name__ == "__main__":
    main()
