"""rastray from Python: a thin layer over librastray's C API, NumPy in and out.

    import numpy as np, rastray
    with rastray.Scene.from_arrays(vertices, faces) as scene:
        cam = rastray.Camera.opencv(K, dist, R, t)
        out = scene.render(cam, size=(640, 480))  # dict of arrays: depth, id, normal, mesh

Arrays come back row 0 at the top, in the library's own memory where it allows
(AOVs are not copied). Ids are uint32 with MISS (0xFFFFFFFF) where nothing is hit;
depth is float32, +inf on a miss. Every failure of the library raises Error with
its one-line message. The calls release the GIL (cffi does) and take `threads`.
"""
import numpy as np

from ._lib import CONSTANTS, ffi, lib

__all__ = ["Error", "Scene", "Camera", "MISS", "METHODS", "AOVS"]

MISS = CONSTANTS["RR_MISS"]  # the id where nothing is hit
MAX_THREADS = CONSTANTS["RR_MAX_THREADS"]
METHODS = [ffi.string(lib.rr_method_name(m)).decode() for m in range(lib.RR_METHOD_COUNT)] + ["auto"]
CAMERAS = [ffi.string(lib.rr_camera_name(c)).decode() for c in range(lib.RR_CAMERA_COUNT)]
AOVS = ("depth", "id", "normal", "bary", "evals", "nodes", "mesh", "material", "coverage", "sample-id",
        "sample-depth", "sample-mesh", "uv", "uv-deriv", "albedo", "direct", "reflection", "shadow", "emission",
        "z-depth", "shadow-lights", "instance")
_HIT = np.dtype([("prim", "<u4"), ("t", "<f4"), ("l1", "<f4"), ("l2", "<f4"), ("geom", "<u4"),
                 ("inst", "<u4")])  # rr_hit
assert _HIT.itemsize == ffi.sizeof("rr_hit")
_DTYPES = {lib.RR_PIXEL_U8: np.uint8, lib.RR_PIXEL_F32: np.float32, lib.RR_PIXEL_U32: np.uint32}


class Error(RuntimeError):
    """A failed call of the library: `code` is its rr_error, the message its one line."""

    def __init__(self, message, code=None):
        super().__init__(message)
        self.code = code


class _Device:
    """One rr_device per object that calls the library: a device serves one thread at a time."""

    def __init__(self):
        dev = lib.rr_device_new()
        if dev == ffi.NULL:
            raise MemoryError("rastray: out of memory for a device")
        self.ptr = ffi.gc(dev, lib.rr_device_release)

    @classmethod
    def building(cls, threads):
        """A device whose scenes build their BVH on `threads` threads (0: all cores)."""
        dev = cls()
        bo = ffi.new("rr_build_options *")
        lib.rr_build_options_init(bo)
        bo.threads = _threads(threads)
        dev.check(lib.rr_device_set_build_options(dev.ptr, bo))
        return dev

    def check(self, code):
        if code != lib.RR_OK:
            raise Error(ffi.string(lib.rr_device_message(self.ptr)).decode("utf-8", "replace"), code)


def _threads(threads):
    if not isinstance(threads, (int, np.integer)) or not 0 <= threads <= MAX_THREADS:
        raise ValueError("threads must be an integer in 0..%d (0: all cores), not %r" % (MAX_THREADS, threads))
    return int(threads)


def _array(a, name, dtype, cols=None, ndim=2):
    """a as a C-contiguous array of dtype (converting only what converts exactly in kind)."""
    a = np.asarray(a)
    kind = np.dtype(dtype).kind
    if a.dtype.kind not in ("f", "i", "u") or (kind in "iu" and a.dtype.kind == "f"):
        raise TypeError("%s must be an array of %s, not %s" % (name, np.dtype(dtype).name, a.dtype))
    if a.ndim != ndim or (cols is not None and a.shape[-1] != cols):
        shape = "(N, %d)" % cols if ndim == 2 else "(3,)"
        raise ValueError("%s must have shape %s, not %s" % (name, shape, a.shape))
    if kind in "iu" and a.size and (a.min() < 0 or a.max() > np.iinfo(dtype).max):
        raise ValueError("%s: values out of range for %s" % (name, np.dtype(dtype).name))
    return np.ascontiguousarray(a, dtype=dtype)


def _vec(v, name):
    v = np.asarray(v, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError("%s must be 3 finite numbers, not %r" % (name, v))
    return [float(x) for x in v]


class Camera:
    """A camera of any kind the CLI knows (`kind`: perspective, orthographic,
    parabolic, latlong, fisheye, cube, opencv, opencv-fisheye) from eye, target, up
    and fov (degrees); the OpenCV kinds are made by Camera.opencv."""

    def __init__(self, eye=(0, 0, 3), target=(0, 0, 0), up=(0, 1, 0), fov=45.0, kind="perspective",
                 ortho_height=0.0):
        if kind not in CAMERAS:
            raise ValueError("unknown camera kind %r (expected one of %s)" % (kind, ", ".join(CAMERAS)))
        self._cam = ffi.new("rr_camera *")
        lib.rr_camera_init(self._cam)
        self._cam.type = CAMERAS.index(kind)
        self._cam.eye, self._cam.target, self._cam.up = _vec(eye, "eye"), _vec(target, "target"), _vec(up, "up")
        self._cam.fov_deg = float(fov)
        self._cam.ortho_height = float(ortho_height)
        self.size = None  # the default image size of render, when known
        dev = _Device()
        dev.check(lib.rr_camera_check(dev.ptr, self._cam))

    @classmethod
    def opencv(cls, K, dist=None, R=np.eye(3), t=np.zeros(3), size=None, fisheye=False):
        """OpenCV's camera: K the 3x3 intrinsics (pixels; skew 0), dist OpenCV's
        coefficients (k1,k2,p1,p2[,k3[,k4,k5,k6]], or k1..k4 with fisheye=True; None:
        none), R (3x3, or a Rodrigues vector of 3) and t the world-to-camera pose
        x_cam = R x + t (x right, y down, z forward); size (w, h) the default image
        size of render."""
        K = np.asarray(K, dtype=np.float64)
        if K.shape != (3, 3) or not np.all(np.isfinite(K)):
            raise ValueError("K must be a finite 3x3 matrix, not %r" % (K,))
        if K[0, 1] != 0 or K[1, 0] != 0 or K[2, 0] != 0 or K[2, 1] != 0 or K[2, 2] != 1:
            raise ValueError("K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)")
        d = np.zeros(0) if dist is None else np.asarray(dist, dtype=np.float64).reshape(-1)
        most = 4 if fisheye else 8
        if d.size > most or not np.all(np.isfinite(d)):
            raise ValueError("dist must be at most %d finite coefficients, not %r" % (most, d))
        R = np.asarray(R, dtype=np.float64)
        if R.size == 3:  # a Rodrigues vector
            R = _rodrigues(R.reshape(3))
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        if R.shape != (3, 3) or t.shape != (3,):
            raise ValueError("R must be 3x3 (or a rotation vector) and t 3 numbers")
        self = cls.__new__(cls)
        self._cam = ffi.new("rr_camera *")
        lib.rr_camera_init(self._cam)
        self._cam.type = CAMERAS.index("opencv-fisheye" if fisheye else "opencv")
        self._cam.fx, self._cam.fy, self._cam.cx, self._cam.cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
        for i, k in enumerate(d):
            self._cam.dist[i] = k
        dev = _Device()
        Rf = ffi.new("float[9]", [float(x) for x in R.reshape(-1)])
        tf = ffi.new("float[3]", [float(x) for x in t])
        dev.check(lib.rr_camera_set_extrinsics(dev.ptr, self._cam, Rf, tf))
        dev.check(lib.rr_camera_check(dev.ptr, self._cam))
        self.size = None if size is None else (int(size[0]), int(size[1]))
        return self

    @property
    def kind(self):
        return CAMERAS[self._cam.type]

    @property
    def eye(self):
        return np.array(list(self._cam.eye), dtype=np.float32)

    @property
    def forward(self):
        """The unit optical axis."""
        f = np.array(list(self._cam.target), dtype=np.float64) - np.array(list(self._cam.eye))
        return f / np.linalg.norm(f)

    def rays(self, size=None):
        """The camera's rays for an image (w, h): origins and unit directions,
        (h, w, 3) float32 each, a zero direction where a pixel has none."""
        w, h = _size(size, self)
        org = np.empty((h, w, 3), dtype=np.float32)
        dirs = np.empty((h, w, 3), dtype=np.float32)
        dev = _Device()
        dev.check(lib.rr_camera_rays(dev.ptr, self._cam, w, h, ffi.from_buffer("float[]", org),
                                     ffi.from_buffer("float[]", dirs)))
        return org, dirs


def _size(size, camera):
    size = size if size is not None else camera.size
    if size is None:
        raise ValueError("give size=(width, height)")
    w, h = size
    if not (isinstance(w, (int, np.integer)) and isinstance(h, (int, np.integer))):
        raise TypeError("size must be two integers (width, height), not %r" % (size,))
    return int(w), int(h)


def _rodrigues(r):
    theta = float(np.linalg.norm(r))
    if theta == 0:
        return np.eye(3)
    k = r / theta
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(theta) * Kx + (1 - np.cos(theta)) * Kx @ Kx


def _image_array(img):
    """An rr_image the library allocated, as an array over its own memory: freed
    (rr_image_free) when the last array using it goes."""
    n = img.width * img.height * img.channels
    dtype = np.dtype(_DTYPES[img.type])
    data = ffi.gc(ffi.cast("char *", img.data), lambda _p, img=img: lib.rr_image_free(img))
    a = np.frombuffer(ffi.buffer(data, n * dtype.itemsize), dtype=dtype)
    return a.reshape(img.height, img.width, img.channels) if img.channels > 1 else a.reshape(img.height, img.width)


class Scene:
    """A committed scene; release it with close() or a with block."""

    def __init__(self, _ptr, _dev):
        self._ptr, self._dev = _ptr, _dev

    @classmethod
    def from_file(cls, path, threads=0):
        """A mesh file assimp reads (.obj .ply .gltf .glb ...) or a built-in scene name."""
        dev = _Device.building(threads)
        out = ffi.new("rr_scene **")
        dev.check(lib.rr_scene_load(dev.ptr, str(path).encode(), out))
        return cls(out[0], dev)

    @classmethod
    def from_arrays(cls, vertices, faces, colors=None, threads=0, spheres=None, planes=None, boxes=None,
                    instances=None):
        """One mesh: vertices (N, 3) float32, faces (M, 3) uint32, colors (N, 3)
        linear RGB per vertex or None. Degenerate and non-finite triangles are
        skipped (they keep their ids). Analytic primitives after it, one geometry
        per kind: spheres (K, 4) centre and radius, planes (K, 6) point and normal,
        boxes (K, 12) centre, half sizes, x and y axes (rr_scene_add_boxes).
        instances (K, 3, 4) affine transforms: the mesh is drawn K times, stored once
        (rr_scene_add_instances; no colors then)."""
        analytic = []
        for arr, name, cols, fn in ((spheres, "spheres", 4, "rr_scene_add_spheres"),
                                    (planes, "planes", 6, "rr_scene_add_planes"),
                                    (boxes, "boxes", 12, "rr_scene_add_boxes")):
            if arr is not None:
                analytic.append((_array(arr, name, np.float32, cols), getattr(lib, fn)))
        v = _array(vertices, "vertices", np.float32, 3)
        f = _array(faces, "faces", np.uint32, 3)
        if f.size and int(f.max()) >= len(v):
            raise ValueError("faces index vertex %d of %d" % (int(f.max()), len(v)))
        c = None if colors is None else _array(colors, "colors", np.float32, 3)
        xf = None if instances is None else _array(np.asarray(instances, np.float32).reshape(-1, 12), "instances",
                                                   np.float32, 12)
        if xf is not None and c is not None:
            raise ValueError("instances take no vertex colors")
        if c is not None and len(c) != len(v):
            raise ValueError("colors must have one row per vertex (%d), not %d" % (len(v), len(c)))
        dev = _Device.building(threads)
        out = ffi.new("rr_scene **")
        dev.check(lib.rr_scene_new(dev.ptr, out))
        self = cls(out[0], dev)
        try:
            vp, fp = ffi.from_buffer("float[]", v), ffi.from_buffer("uint32_t[]", f)
            cp = ffi.NULL if c is None else ffi.from_buffer("float[]", c)
            if xf is None:
                dev.check(lib.rr_scene_add_mesh_colors(self._ptr, vp, len(v), fp, len(f), ffi.NULL, cp))
            else:
                dev.check(lib.rr_scene_add_instances(self._ptr, vp, len(v), fp, len(f), ffi.NULL,
                                                     ffi.from_buffer("float[]", xf), len(xf)))
            for a, add in analytic:
                dev.check(add(self._ptr, ffi.from_buffer("float[]", a), len(a), ffi.NULL))
            dev.check(lib.rr_scene_commit(self._ptr))
        except BaseException:
            self.close()
            raise
        return self

    def close(self):
        """Releases the scene; using it afterwards raises Error."""
        if self._ptr is not None:
            lib.rr_scene_release(self._ptr)
            self._ptr = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def _scene(self):
        if self._ptr is None:
            raise Error("the scene was released")
        return self._ptr

    @property
    def info(self):
        """rr_scene_info as a dict."""
        i = ffi.new("rr_scene_info *")
        self._dev.check(lib.rr_scene_get_info(self._scene(), i))
        return {"triangles": i.triangles, "skipped": i.skipped, "geometries": i.geometries,
                "spheres": i.spheres, "planes": i.planes, "boxes": i.boxes, "instances": i.instances,
                "bounds": (np.array(list(i.bounds_min)), np.array(list(i.bounds_max)))}

    def frame_camera(self, size, fov=45.0):
        """A perspective camera framing the scene as the CLI does without --eye."""
        cam = Camera(fov=fov)
        self._dev.check(lib.rr_camera_frame(self._dev.ptr, self._scene(), size[0], size[1], cam._cam))
        return cam

    def _frame(self, camera, size, method, aa, threads, cull_backfaces):
        w, h = _size(size, camera)
        opt = ffi.new("rr_render_options *")
        lib.rr_render_options_init(opt)
        if method not in METHODS:
            raise ValueError("unknown method %r (expected one of %s)" % (method, ", ".join(METHODS)))
        opt.method = lib.rr_method_from_name(method.encode())
        opt.width, opt.height, opt.threads = w, h, _threads(threads)
        opt.cull_backfaces = int(bool(cull_backfaces))
        dev = _Device()  # one per call: calls on one scene may come from several threads
        if aa is not None:  # "none", "ssaa:N", "msaa:N", "csaa:K/N"
            modes = [ffi.string(lib.rr_aa_mode_name(m)).decode() for m in range(lib.RR_AA_MODE_COUNT)]
            mode, _, count = str(aa).partition(":")
            stored, _, total = count.partition("/")
            if mode not in modes or not all(x.isdigit() for x in (stored or "1", total or "1")):
                raise ValueError("bad aa %r (expected none, ssaa:N, msaa:N or csaa:K/N)" % (aa,))
            samples, kept = (int(total), int(stored)) if total else (int(stored or 1), 0)
            dev.check(lib.rr_render_options_set_aa(dev.ptr, opt, modes.index(mode), samples, kept,
                                                   lib.RR_AA_STANDARD, 1))
        out = ffi.new("rr_frame **")
        dev.check(lib.rr_render(dev.ptr, self._scene(), camera._cam, opt, out))
        # the frame goes before its device (the closure keeps the device alive)
        return ffi.gc(out[0], lambda f, dev=dev: lib.rr_frame_release(f)), dev

    def render(self, camera, size=None, method="auto", aa=None, aovs=("depth", "id", "normal", "mesh"), threads=0,
               cull_backfaces=False):
        """Visibility from camera into a dict of arrays, one per AOV name (AOVS: those
        of the CLI's --aov; "z-depth" is the distance along the optical axis, "depth"
        the distance from the eye). The arrays are (h, w) or (h, w, channels), row 0 at the top;
        ids uint32 (MISS on a miss), the rest float32; "stats" holds S, E, N and the
        method that ran."""
        frame, dev = self._frame(camera, size, method, aa, threads, cull_backfaces)
        result = {}
        for name in aovs:
            a = lib.rr_aov_from_name(str(name).encode())
            if a < 0:
                raise ValueError("unknown AOV %r (expected one of %s)" % (name, ", ".join(AOVS)))
            img = ffi.new("rr_image *")
            dev.check(lib.rr_frame_aov(dev.ptr, self._scene(), camera._cam, frame, a, img))
            result[name] = _image_array(img)
        st = ffi.new("rr_stats *")
        dev.check(lib.rr_frame_get_stats(frame, st))
        result["stats"] = {"setups": st.setups, "edge_evals": st.edge_evals, "nodes": st.nodes,
                           "method": ffi.string(lib.rr_method_name(st.method)).decode(), "frame_ms": st.frame_ms}
        return result

    def shade(self, camera, size=None, mode="lit", method="auto", aa=None, threads=0):
        """The colour image: (linear H×W×3 float32, sRGB-encoded H×W×3 uint8)."""
        m = lib.rr_shade_from_name(str(mode).encode())
        if m < 0:
            raise ValueError("unknown shade mode %r" % (mode,))
        frame, dev = self._frame(camera, size, method, aa, threads, False)
        img = ffi.new("rr_image *")
        dev.check(lib.rr_shade(dev.ptr, self._scene(), camera._cam, frame, m, img))
        linear = _image_array(img)
        x = np.clip(linear, 0, 1).astype(np.float64)
        srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
        return linear, np.round(srgb * 255).astype(np.uint8)

    def _stream(self, rays, tmax=None):
        """A ray stream over the caller's (N, 6) array itself: one stride serves every
        component, so the ranges sit in an (N, 6) array of their own (columns 0, 1)."""
        r = _array(rays, "rays", np.float32, 6)
        n = len(r)
        ranges = np.zeros((n, 6), dtype=np.float32)
        ranges[:, 1] = np.inf if tmax is None else np.broadcast_to(np.asarray(tmax, dtype=np.float32), (n,))
        s = ffi.new("rr_ray_stream *")
        s.count, s.stride = n, 24
        base, rng = ffi.from_buffer("float[]", r), ffi.from_buffer("float[]", ranges)
        for k in range(3):
            s.org[k] = base + k
            s.dir[k] = base + 3 + k
        s.tmin, s.tmax = rng, rng + 1
        return s, (r, base, ranges, rng)

    def intersect(self, rays, threads=0, normals=True):
        """Closest hits of rays (N, 6) float32 (origin, direction) through the ray
        streams, as Open3D's cast_rays: t_hit (+inf on a miss), primitive_ids and
        geometry_ids (MISS on a miss), instance_ids (MISS where no instance), primitive_uvs (barycentrics λ1, λ2) and, with
        normals, primitive_normals (unit geometric normals, 0 on a miss). The first
        four are views into the library's array of hits (strided, not copied)."""
        s, keep = self._stream(rays)
        n = s.count
        hits = np.empty(n, dtype=_HIT)
        if n:
            dev = _Device()
            dev.check(lib.rr_intersect_stream(dev.ptr, self._scene(), s, _threads(threads),
                                              ffi.from_buffer("rr_hit[]", hits)))
        words = hits.view(np.float32).reshape(n, len(_HIT.names))
        out = {"t_hit": hits["t"], "primitive_ids": hits["prim"], "geometry_ids": hits["geom"],
               "instance_ids": hits["inst"], "primitive_uvs": words[:, 2:4]}
        if normals:
            prim = np.ascontiguousarray(hits["prim"])
            out["primitive_normals"] = np.zeros((n, 3), dtype=np.float32)
            if n:
                self._dev.check(lib.rr_scene_get_normals(self._scene(), ffi.from_buffer("uint32_t[]", prim), n,
                                                         ffi.from_buffer("float[]", out["primitive_normals"])))
        return out

    def occluded(self, rays, tmax=None, threads=0):
        """Whether each ray (N, 6) hits anything with 0 <= t <= tmax (scalar or (N,);
        None: infinity), as a bool array."""
        s, keep = self._stream(rays, tmax)
        occ = np.zeros(s.count, dtype=np.intc)
        if s.count:
            dev = _Device()
            dev.check(lib.rr_occluded_stream(dev.ptr, self._scene(), s, _threads(threads),
                                                   ffi.from_buffer("int[]", occ)))
        return occ.astype(bool)


from .importers import colmap_cameras, nerf_cameras  # noqa: E402  (they use Camera)

__all__ += ["colmap_cameras", "nerf_cameras"]
