#!/usr/bin/env python3
"""Zoomed crops of the demo scene without anti-aliasing and with msaa:16 and
csaa:4/16, for the README: renders each through the CLI as linear float colour
(.npy), crops the same window, enlarges it with square pixels, encodes sRGB and
writes docs/aa-<mode>.png. Usage: bench/aa_crops.py [BUILD_DIR] (default build)."""
import os
import struct
import subprocess
import sys
import tempfile
import zlib

import numpy as np

WINDOW = (300, 205, 80, 60)  # x, y, width, height: the teapot's spout and lid
ZOOM = 5


def srgb8(linear):
    c = np.clip(linear, 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return (s * 255 + 0.5).astype(np.uint8)


def write_png(path, rgb):
    h, w, _ = rgb.shape
    raw = b"".join(b"\0" + rgb[y].tobytes() for y in range(h))  # filter 0 on every row

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    x, y, w, h = WINDOW
    with tempfile.TemporaryDirectory() as tmp:
        for mode in ("none", "msaa:16", "csaa:4/16"):
            npy = os.path.join(tmp, "frame.npy")
            subprocess.run([os.path.join(build, "rastray"), "render", "demo", "--size", "640x480", "--aa", mode,
                            "-o", npy], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            crop = np.load(npy)[y:y + h, x:x + w]
            big = np.repeat(np.repeat(srgb8(crop), ZOOM, axis=0), ZOOM, axis=1)
            out = "docs/aa-%s.png" % mode.replace(":", "").replace("/", "-")
            write_png(out, big)
            print("wrote", out)


if __name__ == "__main__":
    main()
