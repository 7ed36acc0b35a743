"""The Python package: arrays equal to the CLI's .npy files byte for byte; projection
agreement with OpenCV (cv2.projectPoints, cv2.fisheye.projectPoints) for random
pinhole, Brown–Conrady and fisheye cameras; ray queries; exceptions on bad input.

Run: python3 -m pytest tests/test_python.py (ctest sets RASTRAY_LIBRARY and RASTRAY_CLI;
from a source tree with build/ they are found by themselves)."""
import os
import subprocess
import sys
import tempfile
import threading

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import rastray  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.environ.get("RASTRAY_CLI", os.path.join(ROOT, "build", "rastray"))


def terrain(n=48, size=8.0, z=4.0):
    """A bumpy grid facing the camera (z forward), its vertices and faces."""
    xs = np.linspace(-size / 2, size / 2, n)
    X, Y = np.meshgrid(xs, xs * 0.75)
    Z = z + 0.4 * np.sin(1.3 * X) * np.cos(1.7 * Y)
    v = np.stack([X, Y, Z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, :-1], i[1:, 1:]
    f = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return v, f.astype(np.uint32)


def random_camera(rng, kind, w, h):
    fx = rng.uniform(0.7, 1.1) * w
    K = np.array([[fx, 0, w / 2 + rng.uniform(-8, 8)], [0, fx * rng.uniform(0.95, 1.05), h / 2 + rng.uniform(-8, 8)],
                  [0, 0, 1]])
    if kind == "pinhole":
        dist = np.zeros(5)
    elif kind == "brown":
        dist = np.array([rng.uniform(-0.25, 0.15), rng.uniform(-0.05, 0.05), rng.uniform(-2e-3, 2e-3),
                         rng.uniform(-2e-3, 2e-3), rng.uniform(-0.01, 0.01)])
    else:
        K[0, 0] *= 0.5
        K[1, 1] = K[0, 0]
        dist = rng.uniform(-0.03, 0.03, 4)
    rvec = rng.uniform(-0.15, 0.15, 3)
    tvec = rng.uniform(-0.3, 0.3, 3)
    return K, dist, rvec, tvec


def fold_radius(dist, fisheye):
    """Where the radial map stops growing (the edge of the field rastray renders)."""
    x = np.linspace(1e-4, np.pi if fisheye else 20, 200000)
    if fisheye:
        k = list(dist) + [0] * (4 - len(dist))
        f = x * (1 + k[0] * x**2 + k[1] * x**4 + k[2] * x**6 + k[3] * x**8)
    else:
        k = list(dist) + [0] * (8 - len(dist))
        r2 = x * x
        f = x * (1 + k[0] * r2 + k[1] * r2**2 + k[4] * r2**3) / (1 + k[5] * r2 + k[6] * r2**2 + k[7] * r2**3)
    bad = np.nonzero(np.diff(f) <= 0)[0]
    return x[bad[0]] if len(bad) else x[-1]


@pytest.fixture(scope="module")
def mesh():
    v, f = terrain()
    with rastray.Scene.from_arrays(v, f) as s:
        yield s, v, f


@pytest.mark.parametrize("kind", ["pinhole", "brown", "fisheye"])
def test_opencv_agreement(mesh, kind):
    """Vertices projected by OpenCV land in pixels whose id is a triangle incident to
    them (or within 0.5 px of one), on >= 99.9% of the visible vertices off the
    mesh's border whose triangles' projected edges are 1 px or longer; and every
    hit point (eye + depth·ray) projects back onto its pixel centre within 1e-3 px."""
    cv2 = pytest.importorskip("cv2")
    scene, v, f = mesh
    w, h = 160, 120
    rng = np.random.default_rng({"pinhole": 1, "brown": 2, "fisheye": 3}[kind])
    incident = [set() for _ in range(len(v))]
    for t, tri in enumerate(f):
        for k in tri:
            incident[k].add(t)
    total_ok = total = 0
    worst_centre = 0.0
    for trial in range(4):
        K, dist, rvec, tvec = random_camera(rng, kind, w, h)
        fisheye = kind == "fisheye"
        cam = rastray.Camera.opencv(K, dist, rvec, tvec, size=(w, h), fisheye=fisheye)
        out = scene.render(cam, aovs=("depth", "id", "z-depth"), method="3dr-bin")
        ids, depth = out["id"], out["depth"]
        # OpenCV's projection of the vertices
        pts = v.astype(np.float64).reshape(-1, 1, 3)
        if fisheye:
            uv, _ = cv2.fisheye.projectPoints(pts, rvec.reshape(1, 1, 3), tvec.reshape(1, 1, 3), K, dist)
        else:
            uv, _ = cv2.projectPoints(pts, rvec, tvec, K, dist)
        uv = uv.reshape(-1, 2)
        R, _ = cv2.Rodrigues(rvec)
        pc = v.astype(np.float64) @ R.T + tvec
        r = np.hypot(pc[:, 0], pc[:, 1]) / pc[:, 2]
        inside_fold = (np.arctan(r) if fisheye else r) < 0.999 * fold_radius(dist, fisheye)
        # visible: nothing between the eye and the vertex (a ray query, independent of the camera model)
        eye = cam.eye.astype(np.float64)
        d = v - eye
        dist_v = np.linalg.norm(d, axis=1)
        rays = np.concatenate([np.broadcast_to(eye, d.shape), d / dist_v[:, None]], axis=1).astype(np.float32)
        hit = scene.intersect(rays)
        visible = np.abs(hit["t_hit"] - dist_v) <= dist_v * 1e-4  # the ray stops at the vertex itself
        interior = np.array([len(s) == 6 for s in incident])  # not on the mesh's border (a silhouette)
        in_image = (uv[:, 0] > 1) & (uv[:, 0] < w - 2) & (uv[:, 1] > 1) & (uv[:, 1] < h - 2)
        # triangles of a pixel or more around the vertex: a smaller one may cover no pixel centre at all
        edge = np.full(len(v), np.inf)
        for a, b in ((0, 1), (1, 2), (2, 0)):
            ln = np.linalg.norm(uv[f[:, a]] - uv[f[:, b]], axis=1)
            np.minimum.at(edge, f[:, a], ln)
            np.minimum.at(edge, f[:, b], ln)
        for k in np.nonzero(visible & in_image & inside_fold & (pc[:, 2] > 0) & (edge >= 1) & interior)[0]:
            u, vv = uv[k]
            near = {(int(np.floor(u + 0.5 + du)), int(np.floor(vv + 0.5 + dv))) for du in (-0.5, 0, 0.5)
                    for dv in (-0.5, 0, 0.5)}
            total += 1
            total_ok += any(ids[y, x] in incident[k] for x, y in near if 0 <= x < w and 0 <= y < h)
        # hit points back onto the pixel centres
        org, dirs = cam.rays((w, h))
        hitmask = np.isfinite(depth)
        P = (org[hitmask] + dirs[hitmask] * depth[hitmask][:, None]).astype(np.float64).reshape(-1, 1, 3)
        if fisheye:
            back, _ = cv2.fisheye.projectPoints(P, rvec.reshape(1, 1, 3), tvec.reshape(1, 1, 3), K, dist)
        else:
            back, _ = cv2.projectPoints(P, rvec, tvec, K, dist)
        ys, xs = np.nonzero(hitmask)
        z = (P.reshape(-1, 3) @ R.T + tvec)[:, 2]  # z-depth: the hit's z in camera axes
        assert np.allclose(out["z-depth"][hitmask], z, rtol=2e-6, atol=0)
        assert np.all(np.isinf(out["z-depth"][~hitmask]))
        err = np.hypot(back.reshape(-1, 2)[:, 0] - xs, back.reshape(-1, 2)[:, 1] - ys)
        worst_centre = max(worst_centre, float(err.max()))
    share = total_ok / total
    print("%s: %d of %d visible vertices in an incident triangle's pixel (%.3f%%); hit points within %.2g px"
          % (kind, total_ok, total, 100 * share, worst_centre))
    assert total > 1000
    assert share >= 0.999
    assert worst_centre < 1e-3 * (10 if kind != "pinhole" else 1)


def cli_npy(tmp, args, aovs):
    cmd = [CLI, "render", "-q"] + args + ["--aov=%s=%s" % (a, os.path.join(tmp, a + ".npy")) for a in aovs]
    subprocess.run(cmd, check=True)
    return {a: open(os.path.join(tmp, a + ".npy"), "rb").read() for a in aovs}


def npy_bytes(a):
    import io
    b = io.BytesIO()
    np.save(b, a)
    return b.getvalue()


@pytest.mark.skipif(not os.path.exists(CLI), reason="the command-line tool is not built")
@pytest.mark.parametrize("which", ["perspective", "opencv", "fisheye"])
def test_equals_cli(which):
    """Arrays equal to the CLI's .npy files byte for byte (same scene, camera, method)."""
    aovs = ("depth", "id", "normal", "mesh", "z-depth")
    w, h = 96, 72
    with rastray.Scene.from_file("demo") as scene, tempfile.TemporaryDirectory() as tmp:
        if which == "perspective":
            cam = rastray.Camera(eye=(0.5, 1.2, 3.0), target=(0, 0.3, 0), fov=50)
            args = ["--eye", "0.5,1.2,3", "--target", "0,0.3,0", "--fov", "50"]
        else:
            fish = which == "fisheye"
            K = np.array([[60.0 if fish else 90.0, 0, 47.5], [0, 60.0 if fish else 88.0, 36.25], [0, 0, 1]])
            dist = [0.02, -0.01, 0.003, -0.001] if fish else [-0.2, 0.04, 0.001, -0.002, 0.0]
            R = np.array([[1, 0, 0], [0, -0.6, -0.8], [0, 0.8, -0.6]], dtype=np.float32)
            eye = np.array([0, 2.0, 1.5])
            t = -R @ eye
            cam = rastray.Camera.opencv(K, dist, R, t, fisheye=fish)
            args = ["--camera", "opencv-fisheye" if fish else "opencv",
                    "--intrinsics", "%r,%r,%r,%r" % (K[0, 0], K[1, 1], K[0, 2], K[1, 2]),
                    "--distortion", ",".join(repr(float(x)) for x in dist),
                    "--extrinsics", ",".join(repr(float(x)) for x in np.concatenate([R.reshape(-1), t]))]
        args += ["demo", "--size", "%dx%d" % (w, h), "--method", "3dr-bb"]
        ref = cli_npy(tmp, args, aovs)
        out = scene.render(cam, size=(w, h), method="3dr-bb", aovs=aovs)
        for a in aovs:
            assert npy_bytes(out[a])[-out[a].nbytes:] == ref[a][-out[a].nbytes:], a
            assert np.array_equal(np.load(os.path.join(tmp, a + ".npy")), out[a], equal_nan=True), a
            assert np.load(os.path.join(tmp, a + ".npy")).dtype == out[a].dtype


def test_render_outputs(mesh):
    scene, v, f = mesh
    cam = rastray.Camera(eye=(0, 0, -2), target=(0, 0, 4), up=(0, -1, 0), fov=60)
    out = scene.render(cam, size=(64, 48), aovs=("depth", "z-depth", "id", "normal", "mesh", "uv"))
    assert out["id"].dtype == np.uint32 and out["id"].shape == (48, 64)
    assert out["normal"].shape == (48, 64, 3) and out["uv"].shape == (48, 64, 2)
    miss = out["id"] == rastray.MISS
    assert np.all(np.isinf(out["depth"][miss])) and np.all(out["mesh"][miss] == rastray.MISS)
    assert np.all(out["z-depth"][~miss] <= out["depth"][~miss] * (1 + 1e-6))
    assert out["depth"].flags["C_CONTIGUOUS"] and out["depth"].base is not None  # the library's memory
    # rays through the ray streams agree with the rendered depth (pinhole: rays from the eye)
    org, dirs = cam.rays((64, 48))
    hit = scene.intersect(np.concatenate([org, dirs], axis=-1).reshape(-1, 6))
    assert np.array_equal(hit["primitive_ids"].reshape(48, 64), out["id"])
    assert np.allclose(hit["t_hit"].reshape(48, 64)[~miss], out["depth"][~miss], rtol=1e-5)
    lin, srgb = scene.shade(cam, size=(64, 48), mode="normal")
    assert lin.shape == (48, 64, 3) and lin.dtype == np.float32 and srgb.dtype == np.uint8


def test_ray_queries(mesh):
    scene, v, f = mesh
    rng = np.random.default_rng(5)
    n = 20000
    org = np.zeros((n, 3), np.float32)
    d = rng.normal(size=(n, 3)).astype(np.float32)
    d[:, 2] = np.abs(d[:, 2]) + 0.5
    rays = np.concatenate([org, d], axis=1)
    one = scene.intersect(rays, threads=1)
    many = scene.intersect(rays, threads=4)
    for k in one:
        assert np.array_equal(one[k], many[k], equal_nan=True), k
    hit = one["primitive_ids"] != rastray.MISS
    assert 0 < hit.sum() < n
    assert np.array_equal(scene.occluded(rays), hit)
    assert not np.any(scene.occluded(rays, tmax=one["t_hit"] * 0.99)[hit])
    nrm = one["primitive_normals"][hit]
    assert np.allclose(np.linalg.norm(nrm, axis=1), 1, atol=1e-5)
    tri = v[f[one["primitive_ids"][hit]]]
    ref = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert np.allclose(nrm, ref / np.linalg.norm(ref, axis=1)[:, None], atol=1e-5)
    # from several Python threads at once (the GIL is released in the calls)
    results = [None] * 4

    def work(i):
        results[i] = scene.intersect(rays)["t_hit"]
    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r, one["t_hit"])


def test_bad_input(mesh):
    scene, v, f = mesh
    with pytest.raises(TypeError):
        rastray.Scene.from_arrays(v, f.astype(np.float32))  # faces must be integers
    with pytest.raises(ValueError):
        rastray.Scene.from_arrays(v[:, :2], f)  # shape
    with pytest.raises(ValueError):
        rastray.Scene.from_arrays(v, f.astype(np.int64) - 1)  # negative index
    with pytest.raises(ValueError):
        rastray.Scene.from_arrays(v[:10], f)  # index out of range
    with pytest.raises(TypeError):
        rastray.Scene.from_arrays(np.array([["a", "b", "c"]]), f[:0])
    # non-contiguous and float64 arrays are taken (copied); NaN vertices make skipped triangles
    vn = np.asfortranarray(v.astype(np.float64))
    vn[0] = np.nan
    with rastray.Scene.from_arrays(vn, f[::2]) as s2:
        assert s2.info["skipped"] >= 1
    with pytest.raises(rastray.Error, match="non-finite"):
        scene.intersect(np.array([[0, 0, 0, np.nan, 0, 1]], np.float32))
    with pytest.raises(ValueError):
        scene.intersect(np.zeros((4, 5), np.float32))
    with pytest.raises(rastray.Error) as e:
        rastray.Scene.from_file("/nonexistent/mesh.obj")
    assert "mesh.obj" in str(e.value)
    with pytest.raises(rastray.Error, match="rotation"):
        rastray.Camera.opencv(np.diag([100.0, 100, 1]), None, np.diag([1.0, 2, 1]), np.zeros(3))
    with pytest.raises(rastray.Error, match="intrinsics"):
        rastray.Camera.opencv(np.array([[-5.0, 0, 1], [0, 5, 1], [0, 0, 1]]))
    with pytest.raises(ValueError):
        rastray.Camera.opencv(np.eye(3), [0.1] * 5, fisheye=True)
    with pytest.raises(ValueError):
        rastray.Camera(kind="nonesuch")
    with pytest.raises(rastray.Error, match="eye equals target"):
        rastray.Camera(eye=(1, 2, 3), target=(1, 2, 3))
    with pytest.raises(rastray.Error, match="field of view"):
        rastray.Camera(fov=200)
    cam = rastray.Camera()
    with pytest.raises(ValueError):
        scene.render(cam, size=(8, 8), method="nonesuch")
    with pytest.raises(ValueError):
        scene.render(cam, size=(8, 8), aovs=("nonesuch",))
    with pytest.raises(rastray.Error, match="size"):
        scene.render(cam, size=(0, 8))
    with pytest.raises(ValueError):
        scene.intersect(np.zeros((1, 6), np.float32), threads=-1)
    s3 = rastray.Scene.from_arrays(v, f)
    s3.close()
    with pytest.raises(rastray.Error, match="released"):
        s3.render(cam, size=(8, 8))
    with pytest.raises(rastray.Error, match="released"):
        s3.intersect(np.zeros((1, 6), np.float32))


def test_readme_quickstart():
    """The README's Python example is python/examples/quickstart.py, which the README's
    commands run (tests/test_readme.py)."""
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    shown = text.split("`python/examples/quickstart.py`:\n\n```python\n", 1)[1].split("```", 1)[0]
    assert shown == open(os.path.join(ROOT, "python", "examples", "quickstart.py"), encoding="utf-8").read()


@pytest.mark.skipif(not os.path.exists(CLI), reason="the command-line tool is not built")
def test_cli_lens_options():
    """--extrinsics from a file equals the values; --save-camera keeps the lens (the
    same bytes again through --camera-file); lens flags without an OpenCV camera and
    bad values are usage errors (exit 2) naming the flag."""
    with tempfile.TemporaryDirectory() as tmp:
        pose = "1,0,0,0,0,1,0,-1,0,0,0,1.2"
        with open(os.path.join(tmp, "pose.txt"), "w") as fp:
            fp.write(pose.replace(",", " ") + "\n")
        base = ["plane:8", "--size", "64x48", "--method", "3dr-bb", "--intrinsics", "40,40,31.5,23.5",
                "--distortion", "-0.3,0.1,0.001,0.001"]
        a = cli_npy(tmp, base + ["--extrinsics", pose, "--save-camera", os.path.join(tmp, "cam.json")], ["id"])
        b = cli_npy(tmp, base + ["--extrinsics", os.path.join(tmp, "pose.txt")], ["id"])
        c = cli_npy(tmp, ["plane:8", "--size", "64x48", "--method", "3dr-bb", "--camera-file",
                          os.path.join(tmp, "cam.json")], ["id"])
        assert a == b == c
        ids = np.load(os.path.join(tmp, "id.npy"))
        assert (ids != rastray.MISS).sum() > 1000
        for args, word in ((["--distortion", "0.1"], "--distortion"), (["--intrinsics", "1,2,3"], "--intrinsics"),
                           (["--extrinsics", "1,0,0,0,2,0,0,0,1,0,0,0"], "rotation"),
                           (["--camera", "opencv", "--intrinsics", "-1,1,1,1"], "intrinsics")):
            p = subprocess.run([CLI, "render", "plane:8", "-o", os.path.join(tmp, "x.png")] + args,
                               capture_output=True, text=True)
            assert p.returncode == 2 and word in p.stderr and p.stderr.count("\n") == 1, (args, p.stderr)
            assert not os.path.exists(os.path.join(tmp, "x.png"))


def test_importers():
    """COLMAP text models and transforms.json give the cameras they describe (the same
    rays as Camera.opencv of the equivalent OpenCV parameters)."""
    R = rastray._rodrigues(np.array([0.1, -0.2, 0.05]))
    t = np.array([0.3, -0.1, 2.0])
    K = np.array([[70.0, 0, 31.2], [0, 72.0, 24.1], [0, 0, 1]])
    dist = [-0.1, 0.02, 0.001, -0.002]
    ref = rastray.Camera.opencv(K, dist, R, t)
    # quaternion of R (w, x, y, z)
    w = np.sqrt(max(0.0, 1 + np.trace(R))) / 2
    q = [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)]
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "cameras.txt"), "w") as f:
            f.write("# comment\n3 OPENCV 64 48 70 72 31.7 24.6 %r %r %r %r\n" % tuple(dist))
        with open(os.path.join(tmp, "images.txt"), "w") as f:
            f.write("# image list\n7 %r %r %r %r %r %r %r 3 view.png\n1.0 2.0 -1\n" % tuple(list(q) + list(t)))
        (name, cam), = rastray.colmap_cameras(tmp)
        assert name == "view.png" and cam.size == (64, 48)
        assert np.allclose(cam.rays()[1], ref.rays((64, 48))[1], atol=1e-5)
        with open(os.path.join(tmp, "cameras.txt"), "w") as f:
            f.write("3 THIN_PRISM_FISHEYE 64 48 1 2 3 4 5 6 7 8 9 10 11 12\n")
        with pytest.raises(ValueError, match="THIN_PRISM_FISHEYE"):
            rastray.colmap_cameras(tmp)
        # transforms.json: camera-to-world in OpenGL's axes
        c2w = np.eye(4)
        c2w[:3, :3] = R.T @ np.diag([1.0, -1, -1])
        c2w[:3, 3] = -R.T @ t
        meta = {"w": 64, "h": 48, "fl_x": 70, "fl_y": 72, "cx": 31.2, "cy": 24.1, "k1": dist[0], "k2": dist[1],
                "p1": dist[2], "p2": dist[3], "frames": [{"file_path": "./a", "transform_matrix": c2w.tolist()}]}
        import json
        with open(os.path.join(tmp, "transforms.json"), "w") as f:
            json.dump(meta, f)
        (name, cam), = rastray.nerf_cameras(os.path.join(tmp, "transforms.json"))
        assert name == "./a"
        assert np.allclose(cam.rays()[1], ref.rays((64, 48))[1], atol=1e-5)
        assert np.allclose(cam.eye, -R.T @ t, atol=1e-5)


def test_analytic_primitives():
    """Spheres, planes and boxes from arrays: counted, rendered (a sphere's hits at the
    closed-form depth), and every method gives the same ids; a bad radius is refused."""
    v = np.array([[3, 0, 0], [4, 0, 0], [3, 1, 0]], np.float32)
    f = np.array([[0, 1, 2]], np.uint32)
    spheres = np.array([[0, 1, 0, 1]], np.float32)
    planes = np.array([[0, 0, 0, 0, 1, 0]], np.float32)
    boxes = np.array([[-3, 0.5, 0, 0.5, 0.5, 0.5, 1, 0, 0, 0, 1, 0]], np.float32)
    with rastray.Scene.from_arrays(v, f, spheres=spheres, planes=planes, boxes=boxes) as s:
        info = s.info
        assert (info["triangles"], info["spheres"], info["planes"], info["boxes"]) == (1, 1, 1, 1)
        ray = np.array([[0, 1, 5, 0, 0, -1]], np.float32)  # at the sphere's centre from +z
        hit = s.intersect(ray)
        assert hit["primitive_ids"][0] == 1 and abs(hit["t_hit"][0] - 4) < 1e-6
        cam = rastray.Camera(eye=(0, 3, 9), target=(0, 0.5, 0), fov=50)
        ids = [s.render(cam, size=(48, 32), method=m, aovs=("id",))["id"] for m in ("rc", "rc-bvh", "3dr-full")]
        assert all(np.array_equal(ids[0], x) for x in ids[1:])
        assert {1, 2, 3} <= set(np.unique(ids[0]).tolist())
    with pytest.raises(rastray.Error, match="sphere 0 has radius"):
        rastray.Scene.from_arrays(v, f, spheres=np.array([[0, 0, 0, -1]], np.float32))


def test_instances():
    """A mesh drawn by transforms: counted once, hits name their instance (intersect's
    instance_ids, the instance AOV), every method the same ids; a mirror is refused."""
    v = np.array([[-1, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    f = np.array([[0, 1, 2]], np.uint32)
    xf = np.array([[[1, 0, 0, x], [0, 1, 0, 0], [0, 0, 1, 0]] for x in (-3, 0, 3)], np.float32)
    with rastray.Scene.from_arrays(v, f, instances=xf) as s:
        info = s.info
        assert (info["triangles"], info["instances"], info["geometries"]) == (3, 3, 3)
        hit = s.intersect(np.array([[3, 0.2, 5, 0, 0, -1], [9, 0.2, 5, 0, 0, -1]], np.float32))
        assert hit["primitive_ids"][0] == 2 and hit["instance_ids"][0] == 2
        assert hit["instance_ids"][1] == rastray.MISS
        cam = rastray.Camera(eye=(0, 0.5, 9), target=(0, 0.5, 0), fov=50)
        out = [s.render(cam, size=(48, 32), method=m, aovs=("id", "instance")) for m in ("rc", "rc-packet", "3dr-bb")]
        assert all(np.array_equal(out[0]["id"], o["id"]) for o in out[1:])
        hits = out[0]["id"] != rastray.MISS
        assert hits.any() and np.array_equal(out[0]["instance"][hits], out[0]["id"][hits])
    with pytest.raises(rastray.Error, match="instance 1 has a mirroring transform"):
        bad = xf.copy()
        bad[1, 0, 0] = -1
        rastray.Scene.from_arrays(v, f, instances=bad)
