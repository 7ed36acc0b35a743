"""Cameras of reconstruction tools as rastray cameras.

colmap_cameras(dir): COLMAP's text model (cameras.txt, images.txt). COLMAP puts the
centre of the top-left pixel at (0.5, 0.5), OpenCV at (0, 0): cx, cy lose 0.5.
Camera models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV,
OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE and RADIAL_FISHEYE (the others have no OpenCV
equivalent and are refused).

nerf_cameras(path): a NeRF / instant-ngp transforms.json: camera_angle_x (or fl_x,
fl_y), optional cx, cy (default w/2, h/2, pixel centres at integers as NeRF's rays),
k1, k2, p1, p2, k3 (k1..k4 with nerfstudio's camera_model OPENCV_FISHEYE) and per
frame a camera-to-world transform_matrix in OpenGL's axes (x right, y up, z back).

Both return a list of (name, Camera) whose size is the image's (w, h).

The parsing is the library's (rr_camera_import), shared with the CLI's --camera-file
and the scene file's camera; a malformed file raises ValueError with its one-line
message naming the file and line or key.
"""
import os

from . import Camera, Error, _Device
from ._lib import ffi, lib


def _import(path):
    path = os.fsencode(path)
    dev = _Device()
    n = ffi.new("int *")
    try:  # counted first, then read (the file is small next to its cameras' memory)
        dev.check(lib.rr_camera_import(dev.ptr, path, ffi.NULL, ffi.NULL, 0, n))
        out = ffi.new("rr_imported_camera[]", max(1, n[0]))
        dev.check(lib.rr_camera_import(dev.ptr, path, ffi.NULL, out, n[0], n))
    except Error as e:
        raise ValueError(str(e)) from None
    cams = []
    for i in range(n[0]):
        c = Camera.__new__(Camera)
        c._cam = ffi.new("rr_camera *", out[i].camera)
        c.size = (out[i].width, out[i].height)
        cams.append((ffi.string(out[i].name).decode("utf-8", "replace"), c))
    return cams


def colmap_cameras(directory):
    """The images of a COLMAP text model as (name, Camera), in images.txt's order."""
    return _import(directory)


def nerf_cameras(path):
    """The frames of a NeRF / instant-ngp transforms.json as (file_path, Camera)."""
    return _import(path)
