#!/usr/bin/env python3
"""Writes data/lights.gltf + data/lights.bin: a glTF 2.0 scene that carries its own
lights (KHR_lights_punctual: a spot, a point and a directional light), its own camera
and metallic-roughness materials -- Spot the cow with its base colour texture
(data/spot_texture.png, referenced by relative URI), a chrome ball (metallic, low
roughness: it mirrors), a rough dielectric block and a ground.

Standard library only. Run from anywhere: python3 scripts/make_gltf_demo.py
"""
import json
import math
import os
import struct

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    n = math.sqrt(sum(x * x for x in a)) or 1.0
    return [x / n for x in a]


def cow():
    """Spot from data/spot.obj (faces v/vt): one glTF vertex per (v, vt) pair,
    smooth normals by position so the seams of the texture do not show."""
    pos, uv, corners = [], [], []
    with open(os.path.join(DATA, "spot.obj")) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                pos.append([float(x) for x in w[1:4]])
            elif w[0] == "vt":
                uv.append([float(w[1]), 1.0 - float(w[2])])  # glTF's UV origin is top-left
            elif w[0] == "f":
                corners.append([tuple(int(i) - 1 for i in c.split("/")[:2]) for c in w[1:4]])
    acc = [[0.0, 0.0, 0.0] for _ in pos]
    for tri in corners:  # area-weighted face normals
        a, b, c = (pos[v] for v, _ in tri)
        n = cross(sub(b, a), sub(c, a))
        for v, _ in tri:
            acc[v] = [acc[v][i] + n[i] for i in range(3)]
    index, P, N, T, I = {}, [], [], [], []
    for tri in corners:
        for key in tri:
            if key not in index:
                index[key] = len(P)
                P.append(pos[key[0]])
                N.append(norm(acc[key[0]]))
                T.append(uv[key[1]])
            I.append(index[key])
    return P, N, T, I


def sphere(r, nu=64, nv=32):
    P, N, T, I = [], [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
            P.append([r * x for x in n])
            N.append(n)
            T.append([i / nu, j / nv])
    for j in range(nv):
        for i in range(nu):
            a, b = j * (nu + 1) + i, (j + 1) * (nu + 1) + i
            if j > 0:  # no zero-area triangles at the poles
                I += [a, b, a + 1]
            if j < nv - 1:
                I += [a + 1, b, b + 1]
    return P, N, T, I


def box(sx, sy, sz):
    P, N, T, I = [], [], [], []
    for axis in range(3):
        for s in (-1, 1):
            n = [0, 0, 0]
            n[axis] = s
            u, v = [0, 0, 0], [0, 0, 0]
            u[(axis + 1) % 3], v[(axis + 2) % 3] = 1, 1
            if s < 0:
                u, v = v, u
            base = len(P)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [n[k] + a * u[k] + b * v[k] for k in range(3)]
                P.append([p[0] * sx / 2, p[1] * sy / 2, p[2] * sz / 2])
                N.append(n)
                T.append([(a + 1) / 2, (b + 1) / 2])
            I += [base, base + 1, base + 2, base, base + 2, base + 3]
    return P, N, T, I


def plane(size):
    h = size / 2
    P = [[-h, 0, -h], [-h, 0, h], [h, 0, h], [h, 0, -h]]
    return P, [[0, 1, 0]] * 4, [[0, 0], [0, 1], [1, 1], [1, 0]], [0, 1, 2, 0, 2, 3]


def look_at(eye, target, up=(0, 1, 0)):
    """Column-major node matrix whose -Z looks from eye to target (glTF cameras and
    spot/directional lights point down their node's -Z)."""
    z = norm(sub(eye, target))
    x = norm(cross(up, z))
    y = cross(z, x)
    return x + [0] + y + [0] + z + [0] + list(eye) + [1]


def yaw(deg):
    a = math.radians(deg) / 2
    return [0, math.sin(a), 0, math.cos(a)]


class Writer:
    def __init__(self):
        self.blob = bytearray()
        self.views, self.accessors = [], []

    def add(self, data, fmt, count, type_, comp, target, minmax=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        raw = struct.pack("<" + fmt * len(data), *data)
        self.views.append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(raw), "target": target})
        self.blob += raw
        acc = {"bufferView": len(self.views) - 1, "componentType": comp, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def mesh(self, name, geo, material):
        P, N, T, I = geo
        flat = lambda rows: [x for r in rows for x in r]
        lo = [min(p[i] for p in P) for i in range(3)]
        hi = [max(p[i] for p in P) for i in range(3)]
        attrs = {"POSITION": self.add(flat(P), "f", len(P), "VEC3", 5126, 34962, (lo, hi)),
                 "NORMAL": self.add(flat(N), "f", len(N), "VEC3", 5126, 34962),
                 "TEXCOORD_0": self.add(flat(T), "f", len(T), "VEC2", 5126, 34962)}
        small = len(P) < 65536
        idx = self.add(I, "H" if small else "I", len(I), "SCALAR", 5123 if small else 5125, 34963)
        return {"name": name, "primitives": [{"attributes": attrs, "indices": idx, "material": material}]}


def main():
    w = Writer()
    materials = [
        {"name": "spot", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                  "metallicFactor": 0.0, "roughnessFactor": 0.55}},
        {"name": "chrome", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.93, 0.88, 1],
                                                    "metallicFactor": 1.0, "roughnessFactor": 0.04}},
        {"name": "terracotta", "pbrMetallicRoughness": {"baseColorFactor": [0.72, 0.26, 0.14, 1],
                                                        "metallicFactor": 0.0, "roughnessFactor": 0.9}},
        {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.55, 0.56, 0.58, 1],
                                                    "metallicFactor": 0.0, "roughnessFactor": 0.8}},
    ]
    meshes = [w.mesh("spot", cow(), 0), w.mesh("ball", sphere(0.55), 1),
              w.mesh("block", box(0.7, 0.7, 0.7), 2), w.mesh("ground", plane(30), 3)]
    lights = [
        {"name": "key", "type": "spot", "color": [1.0, 0.88, 0.72], "intensity": 70,
         "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.7}},
        {"name": "rim", "type": "point", "color": [0.45, 0.6, 1.0], "intensity": 9},
        {"name": "fill", "type": "directional", "color": [0.8, 0.85, 1.0], "intensity": 1.0},
    ]
    light = lambda i: {"KHR_lights_punctual": {"light": i}}
    nodes = [
        {"name": "spot", "mesh": 0, "translation": [0.15, 0.7368, -0.1], "rotation": yaw(150)},
        {"name": "ball", "mesh": 1, "translation": [-1.25, 0.55, 0.75]},
        {"name": "block", "mesh": 2, "translation": [1.55, 0.35, -0.45], "rotation": yaw(25)},
        {"name": "ground", "mesh": 3},
        {"name": "key", "matrix": look_at([2.2, 4.2, 3.0], [0.0, 0.4, 0.0]), "extensions": light(0)},
        {"name": "rim", "translation": [-2.6, 1.9, -1.4], "extensions": light(1)},
        {"name": "fill", "matrix": look_at([-3, 4, 2], [0, 0, 0]), "extensions": light(2)},
        {"name": "view", "camera": 0, "matrix": look_at([0.6, 1.7, 6.2], [0.0, 0.6, 0.0])},
    ]
    gltf = {
        "asset": {"version": "2.0", "generator": "rastray scripts/make_gltf_demo.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"name": "view", "type": "perspective",
                     "perspective": {"yfov": math.radians(34), "aspectRatio": 1.6, "znear": 0.1}}],
        "meshes": meshes,
        "materials": materials,
        "textures": [{"source": 0, "sampler": 0}],
        "images": [{"uri": "spot_texture.png"}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987}],
        "buffers": [{"byteLength": len(w.blob), "uri": "lights.bin"}],
        "bufferViews": w.views,
        "accessors": w.accessors,
    }
    with open(os.path.join(DATA, "lights.bin"), "wb") as f:
        f.write(w.blob)
    with open(os.path.join(DATA, "lights.gltf"), "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
