/* rastray — ray casting and rasterization as one algorithm.
 *
 * One public header. Objects are opaque handles created and released in pairs;
 * every call returns an rr_error and leaves a one-line message in its device
 * (rr_device_message). There is no global mutable state: two devices never
 * share anything. Option structs are filled with defaults by their _init()
 * function so fields can be added later without breaking callers. */
#ifndef RASTRAY_H
#define RASTRAY_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Marks the API's functions: the library is built with hidden visibility, so these
 * are the only symbols its shared object exports. */
#if defined(__GNUC__)
#define RR_API __attribute__((visibility("default")))
#else
#define RR_API
#endif

#define RR_VERSION "0.1.0"
#define RR_MISS 0xFFFFFFFFu /* the id (primitive, geometry, material) where nothing is hit */
#define RR_MAX_SIZE 16384   /* largest image side accepted */
#define RR_MAX_SAMPLES 16   /* most samples per pixel */
#define RR_MAX_THREADS 256  /* most threads an option may ask for */

typedef enum rr_error {
  RR_OK = 0,
  RR_ERROR_ARGUMENT,    /* a bad value passed by the caller */
  RR_ERROR_IO,          /* a file could not be opened, read or written */
  RR_ERROR_PARSE,       /* a file was read but its content is not understood */
  RR_ERROR_EMPTY,       /* a scene with nothing to render */
  RR_ERROR_MEMORY,      /* an allocation failed */
  RR_ERROR_UNSUPPORTED  /* a valid request this build or method cannot do */
} rr_error;

typedef struct rr_device rr_device; /* owns error state; one per thread of control */
typedef struct rr_scene rr_scene;   /* geometries of triangles, attributes, materials, BVH */
typedef struct rr_frame rr_frame;   /* a visibility buffer plus its statistics */

/* Creates a device; returns NULL only when out of memory. */
RR_API rr_device *rr_device_new(void);
/* Releases a device; its scenes and frames must be released first. A device keeps
 * the large work buffers of its renders for the next render (fresh pages cost a
 * page fault each, every frame), as large as the largest render needed (rc-bvh on a
 * 2.3M-triangle scene: ~300 MB) until it is released. */
RR_API void rr_device_release(rr_device *dev);
/* The code of the device's last failed call (RR_OK after a success). */
RR_API rr_error rr_device_error(const rr_device *dev);
/* A one-line message about the device's last failed call ("" after a success). */
RR_API const char *rr_device_message(const rr_device *dev);

/* ---- progress ------------------------------------------------------------ */

/* The stages of the calls that report their progress. */
typedef enum rr_progress_stage {
  RR_PROGRESS_LOAD = 0, /* rr_scene_load reading a file or making a built-in scene (reports 0 and 1 only) */
  RR_PROGRESS_BUILD,    /* building the BVH (rr_scene_commit, and rr_scene_load through it) */
  RR_PROGRESS_RENDER,   /* a visibility pass of rr_render, by tiles, rows or batches of triangles */
  RR_PROGRESS_STAGE_COUNT
} rr_progress_stage;

/* Told that `fraction` (0..1) of `stage` is done; `user` is rr_device_set_progress's. */
typedef void (*rr_progress_fn)(void *user, rr_progress_stage stage, double fraction);

/* Sets the function this device's calls report their progress to (fn NULL: none,
 * the default, and reporting then costs nothing). A stage is reported at 0 when it
 * starts, at 1 when it ends and in between at most every RR_PROGRESS_MS, with
 * fractions that do not decrease (a call that fails may stop short of 1); one call
 * may run a stage more than once (auto renders trials at a smaller size before the
 * frame), each run starting from 0.
 * Threading: fn is called only on the thread that made the call and from inside
 * it, never from the library's worker threads, so never concurrently for one
 * device (devices used by different threads may call it concurrently, each on its
 * own thread). It should return quickly and must not use this device. */
RR_API rr_error rr_device_set_progress(rr_device *dev, rr_progress_fn fn, void *user);
#define RR_PROGRESS_MS 50 /* least time between two reports of a stage's inner fractions */

/* ---- scenes -------------------------------------------------------------- */

/* Loads a scene from a file that assimp reads (OBJ, PLY, glTF, COLLADA, 3DS...),
 * a scene file (a path ending in ".json": rr_scene_load_file with default options)
 * or from a built-in name: "demo", "plane[:N]", "sphere:N", "box[:N]", "torus[:N]"
 * (meshes), "sphere" (the analytic unit sphere), "grid:PATH:N" (N×N copies of a
 * mesh on the XZ plane), "ground" (an analytic infinite plane with an analytic
 * sphere and a box mesh on it), "ground:inf" (the same with the plane of vertices
 * at infinity), "checker" (an infinite
 * checkerboard-textured plane, with a grazing view of its own). "demo" reads meshes from
 * the first directory holding them: $RASTRAY_DATA, the installed share/rastray,
 * the source tree's data/. */
RR_API rr_error rr_scene_load(rr_device *dev, const char *path, rr_scene **out);
/* Creates an empty scene to be filled with rr_scene_add_mesh. */
RR_API rr_error rr_scene_new(rr_device *dev, rr_scene **out);
/* Appends an indexed triangle mesh as one new geometry (numbered after the scene's
 * others) with a new material of base colour rgb (NULL: grey); 3 indices per
 * triangle. Degenerate and non-finite triangles are skipped and counted; they keep
 * their ids (see "ids" below), so triangle t of the call has id first + t. */
RR_API rr_error rr_scene_add_mesh(rr_scene *scene, const float *positions, size_t nvertices,
                                  const uint32_t *indices, size_t ntriangles, const float rgb[3]);
/* The same with a colour per vertex (vertex_rgb: 3 floats each, linear RGB like
 * glTF's COLOR_0; NULL: none, as rr_scene_add_mesh), interpolated across each
 * triangle and multiplied into the base colour rgb (NULL here: white). */
RR_API rr_error rr_scene_add_mesh_colors(rr_scene *scene, const float *positions, size_t nvertices,
                                         const uint32_t *indices, size_t ntriangles, const float rgb[3],
                                         const float *vertex_rgb);
/* The same with homogeneous xyzw vertices: w != 0 is divided out, w = 0 is a point at infinity in direction xyz (3D methods only). */
RR_API rr_error rr_scene_add_mesh4(rr_scene *scene, const float *xyzw, size_t nvertices, const uint32_t *indices,
                                   size_t ntriangles, const float rgb[3]);
/* Appends `count` analytic spheres as one new geometry (numbered after the scene's
 * others, one id per sphere like a mesh's triangles) with a new material of base
 * colour rgb (NULL: grey). spheres: 4 floats each, centre x, y, z and radius. A
 * radius that is not positive, or a value that is not finite, refuses the whole
 * call (RR_ERROR_ARGUMENT, the message naming the sphere) and adds nothing. A hit's
 * l1, l2 (rr_hit, the visibility buffer) are its longitude / 2π + 0.5 (atan2 of x
 * over z) and colatitude / π from +y. */
RR_API rr_error rr_scene_add_spheres(rr_scene *scene, const float *spheres, size_t count, const float rgb[3]);
/* Appends `count` analytic infinite planes as one geometry, like rr_scene_add_spheres.
 * planes: 6 floats each, a point x, y, z on the plane and its normal (any length
 * but zero; both sides are seen). A hit's l1, l2 are its offsets from the point
 * along two axes of the plane (u across the normal in the plane of its two largest
 * components, v = n × u). */
RR_API rr_error rr_scene_add_planes(rr_scene *scene, const float *planes, size_t count, const float rgb[3]);
/* Appends `count` analytic boxes as one geometry, like rr_scene_add_spheres. boxes:
 * 12 floats each: the centre x, y, z, the half sizes along the box's axes (positive),
 * and its x and y axes in world space (any lengths, not parallel: made unit and
 * orthogonal, x first; z = x × y). An axis-aligned box has axes 1,0,0 and 0,1,0. A
 * hit's l1 is face + u (face = 2·axis + 1 on the positive side, 0 .. 5), l2 is v,
 * (u, v) the hit's position on the face over [0, 1]². */
RR_API rr_error rr_scene_add_boxes(rr_scene *scene, const float *boxes, size_t count, const float rgb[3]);
/* Appends an indexed triangle mesh (as rr_scene_add_mesh) drawn `count` times,
 * instance k moved by the affine transform transforms[12k .. 12k+11] (3×4 row-major:
 * world = M·p + t, rows (m00 m01 m02 tx), (m10 ..), (m20 ..)), like Embree's instance
 * geometry: the mesh is stored once. In ids and geometries the instances read as
 * the mesh copied `count` times in a row: instance k's triangle t has id
 * first + k·F + t (F: the mesh's triangles, skipped ones too) and its own copy of
 * the geometry; rr_scene_get_instance tells them apart. A scene holds one instanced
 * mesh. A transform that is not finite, singular or mirroring (negative
 * determinant) refuses the call (RR_ERROR_ARGUMENT, the message naming the
 * instance) and adds nothing. */
RR_API rr_error rr_scene_add_instances(rr_scene *scene, const float *positions, size_t nvertices,
                                       const uint32_t *indices, size_t ntriangles, const float rgb[3],
                                       const float *transforms, size_t count);
/* The instance holding primitive id `prim` (RR_MISS when it is no instance's, and
 * for RR_MISS) and prim's id within the instanced mesh (*local: as if the mesh were
 * alone in the scene from its first id). Either pointer may be NULL. */
RR_API rr_error rr_scene_get_instance(const rr_scene *scene, uint32_t prim, uint32_t *instance, uint32_t *local);
/* Builds what rendering needs (the BVH); called implicitly by rr_scene_load.
 * Uses the device's build options (rr_device_set_build_options). */
RR_API rr_error rr_scene_commit(rr_scene *scene);

typedef struct rr_build_options {
  int threads;   /* threads building the BVH; 0: all cores (at most RR_MAX_THREADS). The tree does not depend on it. */
  int bins;      /* SAH bins per axis, 2..64 (default 32) */
  int leaf_size; /* most triangles in a leaf, 1..64 (default 4) */
} rr_build_options;

/* Fills build options with defaults: all cores, 32 bins, leaves of at most 4 triangles. */
RR_API void rr_build_options_init(rr_build_options *opt);
/* Sets the options that later commits of this device's scenes use (like Embree's
 * device "threads=N"); rr_scene_load commits, so set them before loading. */
RR_API rr_error rr_device_set_build_options(rr_device *dev, const rr_build_options *opt);
/* Releases a scene. */
RR_API void rr_scene_release(rr_scene *scene);

/* How files are imported (rr_scene_load, and the built-ins that read files). By
 * default assimp runs in a child process: a crash, a hang or a runaway allocation
 * in the importer then fails the call (RR_ERROR_PARSE, a message naming the file
 * and the cause) instead of taking the caller down. Before that, the formats that
 * declare counts (PLY, OFF, binary STL, GLB) are checked against the file's size. */
typedef struct rr_import_limits {
  double timeout_s;    /* longest an import may take, seconds; 0: no limit (default 60) */
  uint64_t max_memory; /* most bytes an import may allocate; 0: no limit (default: half the physical memory) */
  int in_process;      /* nonzero: import in the calling process (no fork; no time or memory limit, and
                          an importer crash is the caller's); the structural checks still run */
  int importer_log;    /* nonzero: the child's importer messages reach stderr (default 0: discarded;
                          in process they go wherever the importer sends them) */
} rr_import_limits;

/* Fills import limits with defaults: 60 s, half the physical memory, in a child process, quiet. */
RR_API void rr_import_limits_init(rr_import_limits *lim);
/* Sets the limits of this device's later imports (like rr_device_set_build_options). */
RR_API rr_error rr_device_set_import_limits(rr_device *dev, const rr_import_limits *lim);

typedef struct rr_scene_info {
  uint64_t triangles;    /* triangles kept */
  uint64_t skipped;      /* degenerate or non-finite triangles dropped at load (never hit; their ids stay taken) */
  uint32_t materials;    /* materials */
  uint32_t geometries;   /* geometries (meshes), ids 0 .. geometries - 1 */
  float bounds_min[3], bounds_max[3];
  /* BVH (zero before it is built) */
  uint64_t bvh_nodes, bvh_leaves;
  uint32_t bvh_depth;
  double bvh_sah_cost;
  double bvh_build_ms;
  uint64_t bvh_bytes;
  uint32_t textures;         /* materials that name a texture */
  uint32_t textures_missing; /* of those, textures not found or not decoded (rr_scene_get_material_info) */
  uint32_t cameras, lights;  /* cameras and lights the file defines */
  float up[3];    /* the model's up direction: +Y unless the file says otherwise (Z-up files: +Z) */
  float front[3]; /* the side the model faces, seen by rr_camera_frame: +Z for Y-up, -Y for Z-up files */
  uint64_t texture_bytes; /* the textures' texels as read and their MIP chains (16-bit linear RGBA) */
  uint64_t spheres, planes, boxes; /* analytic primitives (not counted in triangles) */
  uint32_t instances;        /* instances of the instanced mesh (rr_scene_add_instances), 0 when none */
  uint64_t stored_triangles; /* triangles stored: triangles less the instances' copies (each mesh once) */
  uint64_t scene_bytes;      /* the primitives' arrays (positions, normals, UVs, ...) and the instances */
} rr_scene_info;

/* Fills what is known about a scene. */
RR_API rr_error rr_scene_get_info(const rr_scene *scene, rr_scene_info *info);

/* ---- geometries ---------------------------------------------------------- */
/* A scene is a list of geometries, each a run of primitives of one kind: a mesh of a
 * file's node/mesh pair, one rr_scene_add_mesh call or one object of a built-in
 * scene, in the order they were added. Primitive ids (the visibility buffer's ids)
 * are global: geometry g holds ids [first, first + count).
 * Ids: a triangle's id is its face's index in load order after fan triangulation
 * (a face of n corners gives triangles (0, j, j+1), j = 1 .. n-2), counted over the
 * whole scene with geometries numbered in load order, whatever was skipped: a
 * skipped (degenerate or non-finite) triangle keeps its id, which no hit ever has,
 * and the triangles after it keep theirs. So triangle t of a mesh (a file's or an
 * rr_scene_add_mesh call's) has id first + t wherever an id appears (rr_frame_ids,
 * the id AOV, rr_hit.prim) and local index t in rr_scene_get_geometry.
 * rr_scene_info.triangles counts kept triangles: ids run from 0 to triangles + skipped - 1. */

/* What a geometry is made of (like Embree's RTC_GEOMETRY_TYPE_*). */
typedef enum rr_geometry_kind {
  RR_GEOMETRY_TRIANGLE = 0, /* a triangle mesh */
  RR_GEOMETRY_SPHERE,       /* analytic spheres (centre, radius): rr_scene_add_spheres */
  RR_GEOMETRY_PLANE,        /* analytic infinite planes (point, normal): rr_scene_add_planes */
  RR_GEOMETRY_BOX,          /* analytic boxes, axis-aligned or oriented: rr_scene_add_boxes */
  RR_GEOMETRY_KIND_COUNT
} rr_geometry_kind;

/* The name of a geometry kind ("triangle"), NULL when out of range. */
RR_API const char *rr_geometry_kind_name(int kind);

typedef struct rr_geometry_info {
  rr_geometry_kind kind;
  uint32_t first, count; /* its primitives: global ids first .. first + count - 1, skipped ones included */
  uint32_t material;     /* the material of all its primitives */
  const char *name;      /* the name the file gives it, NULL when none; valid until the scene changes */
} rr_geometry_info;

/* The geometry holding primitive id `prim` (a skipped one's too) and prim's index
 * within it, its face's index in the mesh (*local = prim - first); RR_MISS maps to
 * RR_MISS in both. Either pointer may be NULL. */
RR_API rr_error rr_scene_get_geometry(const rr_scene *scene, uint32_t prim, uint32_t *geom, uint32_t *local);
/* Fills what is known about geometry `geom` (0 .. rr_scene_info.geometries - 1). */
RR_API rr_error rr_scene_get_geometry_info(const rr_scene *scene, uint32_t geom, rr_geometry_info *info);
/* The unit geometric normals (p1 - p0) × (p2 - p0) of n triangles by id, 3 floats each
 * into normals; zero for RR_MISS and ids of skipped triangles. */
RR_API rr_error rr_scene_get_normals(const rr_scene *scene, const uint32_t *prims, size_t n, float *normals);

/* ---- ray queries --------------------------------------------------------- */

/* An arbitrary ray: points org + t·dir for tmin <= t <= tmax (dir need not be unit). */
typedef struct rr_ray {
  float org[3], dir[3];
  float tmin, tmax;
} rr_ray;

typedef struct rr_hit {
  uint32_t prim; /* triangle id (see "ids" above), RR_MISS when nothing is hit */
  float t;       /* ray parameter of the hit (+inf on a miss) */
  float l1, l2;  /* barycentrics of the hit: weights of the triangle's vertices 1 and 2 */
  uint32_t geom; /* the geometry holding prim (rr_scene_get_geometry), RR_MISS on a miss */
  uint32_t inst; /* the instance holding prim (rr_scene_get_instance), RR_MISS when none */
} rr_hit;

/* Threading: rr_intersect and rr_occluded only read the scene, so any number of
 * threads may call them at once on one committed scene, each passing its own
 * device (or NULL). A device records the outcome of every call made with it, so
 * it serves one thread at a time. Nothing may change or release the scene
 * (rr_scene_add_mesh, rr_scene_commit, rr_scene_release) while queries run. */

/* Closest hit of a ray through the committed scene's BVH, with the one sample test
 * of every method (ties in t go to the lower id; a ray through a shared edge hits
 * exactly one triangle). Needs a committed scene. The outcome goes to dev, which
 * may be NULL (then only the returned code tells it). */
RR_API rr_error rr_intersect(rr_device *dev, const rr_scene *scene, const rr_ray *ray, rr_hit *hit);
/* Whether the ray hits any triangle with tmin <= t <= tmax (*occluded = 0 or 1);
 * dev as for rr_intersect. */
RR_API rr_error rr_occluded(rr_device *dev, const rr_scene *scene, const rr_ray *ray, int *occluded);

/* Many rays at once: a stream of `count` rays in either layout, described by
 * where ray 0's components are and the bytes from one ray's component to the
 * next's. An array of rr_ray: rr_ray_stream_aos(rays, count). Separate arrays
 * (structure of arrays): {.count = n, .stride = sizeof(float), .org = {ox, oy, oz},
 * .dir = {dx, dy, dz}, .tmin = tmin, .tmax = tmax}. */
typedef struct rr_ray_stream {
  size_t count;
  size_t stride; /* a multiple of sizeof(float) */
  const float *org[3], *dir[3], *tmin, *tmax;
} rr_ray_stream;
RR_API rr_ray_stream rr_ray_stream_aos(const rr_ray *rays, size_t count);

/* rr_intersect and rr_occluded for every ray of a stream, on `threads` threads
 * (0: all cores; at most RR_MAX_THREADS), into hits[i] / occluded[i]: each result
 * is bit for bit the one rr_intersect / rr_occluded gives for that ray alone,
 * whatever the thread count. A ray those would refuse (a non-finite origin or
 * direction, a zero direction, a NaN range) is a miss (occluded 0) and the other
 * rays are still traced; the call then returns RR_ERROR_ARGUMENT naming the
 * lowest such ray. count 0 does nothing. Threading as for rr_intersect: any
 * number of threads may run streams and single queries on one committed scene
 * at once, each with its own device (or NULL); the threads a stream starts only
 * read the scene and write their own rays' results. */
RR_API rr_error rr_intersect_stream(rr_device *dev, const rr_scene *scene, const rr_ray_stream *rays, int threads,
                                    rr_hit *hits);
RR_API rr_error rr_occluded_stream(rr_device *dev, const rr_scene *scene, const rr_ray_stream *rays, int threads,
                                   int *occluded);

/* ---- cameras ------------------------------------------------------------- */

/* With u = 2(x+0.5)/W - 1, v = 1 - 2(y+0.5)/H and the camera basis right, up, fwd: */
typedef enum rr_camera_type {
  RR_CAMERA_PERSPECTIVE = 0, /* pinhole; fov_deg is the vertical field of view */
  RR_CAMERA_ORTHOGRAPHIC,    /* rays along fwd from eye + u·(h·aspect/2)·right + v·(h/2)·up, h = ortho_height */
  RR_CAMERA_PARABOLIC,       /* hemisphere around fwd: d = u·right + v·up + (1 - u² - v²)/2·fwd, u²+v² <= 1 */
  RR_CAMERA_LATLONG,         /* 360°×180° panorama: φ = 2π(x+0.5)/W - π, θ = π(y+0.5)/H */
  RR_CAMERA_FISHEYE,         /* equidistant: r = √(u²+v²) <= 1, angle from fwd = r·fov_deg/2 (fov up to 360) */
  RR_CAMERA_CUBE,            /* six 90° faces in a horizontal cross (image 4F × 3F) */
  RR_CAMERA_OPENCV,          /* OpenCV's pinhole with Brown–Conrady distortion (cv::projectPoints), below */
  RR_CAMERA_OPENCV_FISHEYE,  /* OpenCV's fisheye, Kannala–Brandt (cv::fisheye::projectPoints), below */
  RR_CAMERA_COUNT
} rr_camera_type;

/* The narrowest field of view, in degrees: narrower ones put a framed eye beyond
 * the range of floats. */
#define RR_FOV_MIN 1e-3f

typedef struct rr_camera {
  rr_camera_type type;
  float eye[3], target[3], up[3];
  float fov_deg;      /* vertical field of view (perspective), full angle (fisheye); at least RR_FOV_MIN */
  float ortho_height; /* orthographic view height; 0: 2·|target - eye|·tan(fov/2) */
  /* The OpenCV cameras: intrinsics in pixels of the rendered image, OpenCV's convention
   * (pixel (x, y)'s centre at (x, y), so rastray's sample (sx, sy) is OpenCV's point
   * (sx - 0.5, sy - 0.5)); the pose is eye, target and up (rr_camera_set_extrinsics
   * sets them from R, t). A point at (a, b, 1) in camera axes (x right = fwd × up,
   * y down, z forward) appears at fx·a' + cx, fy·b' + cy with (a', b') its distorted
   * image: opencv: r² = a² + b², a' = a·q + 2p1·ab + p2(r² + 2a²), b' = b·q + p1(r² + 2b²)
   * + 2p2·ab, q = (1 + k1r² + k2r⁴ + k3r⁶) / (1 + k4r² + k5r⁴ + k6r⁶); fisheye: θ = atan r,
   * θd = θ(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸), (a', b') = (θd / r)(a, b). A pixel's ray
   * inverts this (Newton's method in double); a pixel outside the image of the map's
   * one-to-one part (beyond the radius where the radial map folds back, fisheye
   * θ >= 180°) has no ray. Rays are unit: the depth AOV is the eye distance. fx = fy = 0
   * (rr_camera_init's): the perspective camera's intrinsics for fov_deg and the image size. */
  float fx, fy, cx, cy;
  float dist[8]; /* opencv: k1 k2 p1 p2 k3 k4 k5 k6 (OpenCV's order); fisheye: k1 k2 k3 k4; zeros: none */
} rr_camera;

/* The camera type named `name` ("perspective", "orthographic", "parabolic", "latlong",
 * "fisheye", "cube"); -1 when unknown. */
RR_API int rr_camera_from_name(const char *name);
/* The name of a camera type, NULL when out of range. */
RR_API const char *rr_camera_name(int type);

/* Fills a camera with defaults: perspective, eye (0,0,3) looking at the origin, y up, 45°. */
RR_API void rr_camera_init(rr_camera *cam);
/* Places eye and target so that the scene's bounds fill the view of cam->fov_deg,
 * looking at the model's front from a little above (rr_scene_info.front and up:
 * from +Z towards -Z with Y up unless the file says otherwise). */
RR_API rr_error rr_camera_frame(rr_device *dev, const rr_scene *scene, int width, int height,
                                rr_camera *cam);
/* Checks a camera (finite values, eye != target, up not parallel to the view). */
RR_API rr_error rr_camera_check(rr_device *dev, const rr_camera *cam);
/* Sets eye, target and up from OpenCV extrinsics, world to camera: x_cam = R·x_world + t
 * (R row-major, a rotation within 1e-3; camera axes x right, y down, z forward). */
RR_API rr_error rr_camera_set_extrinsics(rr_device *dev, rr_camera *cam, const float R[9], const float t[3]);
/* The rays of a camera for a width × height image, one per pixel centre, row 0 at the
 * top: origins org[3·i] and unit directions dir[3·i] of pixel i = y·width + x (either
 * may be NULL); a pixel without a ray gets a zero direction. Orthographic rays are
 * along the view; every other camera's leave the eye. */
RR_API rr_error rr_camera_rays(rr_device *dev, const rr_camera *cam, int width, int height, float *org, float *dir);

/* ---- materials, cameras and lights of a file ------------------------------- */

/* Where a material's texture came from, or why it has none. */
typedef enum rr_texture_status {
  RR_TEXTURE_NONE = 0,   /* the material names no texture */
  RR_TEXTURE_FILE,       /* read from a file (beside the scene; case and '\\' separators forgiven) */
  RR_TEXTURE_EMBEDDED,   /* read from inside the scene file (GLB, data URI, ZAE, FBX) */
  RR_TEXTURE_MISSING,    /* named, but not found: shaded with the base colour alone */
  RR_TEXTURE_UNREADABLE, /* found, but not decoded (format, size): shaded with the base colour alone */
  RR_TEXTURE_STATUS_COUNT
} rr_texture_status;

/* The name of a texture status ("none", "file", "embedded", "missing", "unreadable"), NULL when out of range. */
RR_API const char *rr_texture_status_name(int status);

/* Which lobes a material's specular part takes (docs/shading.md). */
typedef enum rr_material_model {
  RR_MATERIAL_PHONG = 0, /* MTL and the other formats: Lambert diffuse + normalised Blinn–Phong (ks, shininess) */
  RR_MATERIAL_PBR,       /* glTF metallic–roughness: Lambert diffuse + GGX microfacet specular */
  RR_MATERIAL_MODEL_COUNT
} rr_material_model;

/* The name of a material model ("phong", "pbr"), NULL when out of range. */
RR_API const char *rr_material_model_name(int model);

/* Textures a material may name besides the base colour's; listed, not yet used in shading. */
typedef enum rr_material_map {
  RR_MAP_SPECULAR = 0,         /* MTL map_Ks */
  RR_MAP_NORMAL,               /* MTL map_Bump / bump / norm, glTF normalTexture */
  RR_MAP_OCCLUSION,            /* glTF occlusionTexture */
  RR_MAP_EMISSIVE,             /* MTL map_Ke, glTF emissiveTexture */
  RR_MAP_METALLIC_ROUGHNESS,   /* glTF metallicRoughnessTexture */
  RR_MAP_COUNT
} rr_material_map;

/* The shading inputs of a material, linear RGB; see docs/shading.md for how they are used. */
typedef struct rr_material_params {
  rr_material_model model;
  float specular[3]; /* phong: Ks, the specular lobe's colour (0: none) */
  float shininess;   /* phong: Ns, the Blinn–Phong exponent (0 .. 10000) */
  float ambient[3];  /* MTL Ka, kept for reference: ambient light comes from the scene's sky (see shading.md) */
  float emission[3]; /* MTL Ke, glTF emissiveFactor: emitted radiance */
  float opacity;     /* MTL d (or 1 - Tr), glTF base colour alpha; 1: opaque (kept; shading is opaque) */
  int illum;         /* MTL illum (-1 when not given); 3: mirror reflection of colour Ks */
  float metallic, roughness; /* pbr: glTF's factors (default 1, 1); roughness below 0.1 is a mirror */
} rr_material_params;

typedef struct rr_material_info {
  const char *name;     /* the file's name for it, NULL when none */
  float color[3];       /* base colour, linear RGB (MTL Kd, glTF baseColorFactor) */
  const char *texture;  /* the base colour texture as the file names it ("*0": the file's first
                           embedded one), NULL when none */
  rr_texture_status texture_status;
  int texture_width, texture_height; /* 0 unless the texture was read */
  rr_material_params params;
  const char *maps[RR_MAP_COUNT]; /* other textures the file names (not yet used), NULL when none */
} rr_material_info;

/* Fills what is known about material `material` (0 .. rr_scene_info.materials - 1);
 * pointers stay valid until the scene is released. */
RR_API rr_error rr_scene_get_material_info(const rr_scene *scene, uint32_t material, rr_material_info *info);
/* Overrides material `material`'s base colour (color NULL: kept) and shading inputs
 * (params NULL: kept), e.g. for a scene file's material overrides: a known model,
 * finite values, colours at least 0, shininess 0 .. 10000, metallic, roughness and
 * opacity 0 .. 1; the texture stays. Not thread-safe: nothing may render meanwhile. */
RR_API rr_error rr_scene_set_material(rr_scene *scene, uint32_t material, const float color[3],
                                      const rr_material_params *params);

/* The file's camera `index` (0 .. rr_scene_info.cameras - 1) as an rr_camera for a
 * width × height image: eye, target one unit along its view, up, and the field of
 * view the file keeps fixed (glTF's vertical one; other formats' horizontal one,
 * converted for the image's aspect); orthographic cameras keep their width. */
RR_API rr_error rr_scene_get_camera(rr_device *dev, const rr_scene *scene, uint32_t index, int width, int height,
                                    rr_camera *cam);
/* The name of the file's camera `index`, NULL when it has none or index is out of range. */
RR_API const char *rr_scene_camera_name(const rr_scene *scene, uint32_t index);
/* The index of the camera named `name`, else of `name` read as a decimal index; when
 * neither exists it fails with a message listing the cameras' names. */
RR_API rr_error rr_scene_find_camera(rr_device *dev, const rr_scene *scene, const char *name, uint32_t *index);

/* Light kinds, as assimp's aiLightSourceType. */
typedef enum rr_light_type {
  RR_LIGHT_UNDEFINED = 0,
  RR_LIGHT_DIRECTIONAL, /* from infinitely far along direction */
  RR_LIGHT_POINT,       /* from position in every direction */
  RR_LIGHT_SPOT,        /* from position, in a cone around direction */
  RR_LIGHT_AMBIENT,     /* everywhere */
  RR_LIGHT_AREA,        /* a size[0] × size[1] rectangle at position facing direction */
  RR_LIGHT_TYPE_COUNT
} rr_light_type;

/* The name of a light type ("directional", ...), NULL when out of range. */
RR_API const char *rr_light_type_name(int type);

/* A light in world space, from a file or rr_scene_add_light; the lit shade mode
 * renders it (docs/shading.md). Units as glTF's KHR_lights_punctual: color is linear
 * RGB with the intensity multiplied in, in candela for point and spot lights
 * (irradiance I/d² lux at distance d, no range cut-off), in lux (irradiance on a
 * surface facing the light) for directional ones, and radiance (nits) for ambient
 * ones, a sky: a white Lambert surface under a directional light of E lux has
 * radiance E/π. Other formats' colours are read in the same units. */
typedef struct rr_light_info {
  const char *name;     /* NULL when none; valid until the scene is released */
  rr_light_type type;
  float position[3];
  float direction[3];   /* unit: where the light shines */
  float color[3];       /* linear RGB with the file's intensity multiplied in (units above) */
  float attenuation[3]; /* constant, linear and quadratic factors as the file gives them (shading
                           uses the inverse square law whatever they say) */
  float inner_cone_deg, outer_cone_deg; /* spot: half-angles from direction (full and no light) */
  float size[2];        /* area: extent (shaded as a point light at position) */
  float ground[3];      /* ambient: radiance from straight below, color being the one from straight
                           above, blended linearly in between along the scene's up (a gradient sky);
                           all 0: color from every direction (a constant sky) */
} rr_light_info;

/* Fills the scene's light `index` (0 .. rr_scene_info.lights - 1). */
RR_API rr_error rr_scene_get_light(const rr_scene *scene, uint32_t index, rr_light_info *info);
/* Adds a light (copied, name too) after the file's: directional, point, spot or
 * ambient (area and undefined ones are refused), with finite values, colours and
 * ground at least 0, a nonzero direction for directional and spot lights (made
 * unit) and, for spot lights, 0 <= inner_cone_deg <= outer_cone_deg <= 90 (both 0:
 * glTF's defaults 0 and 45). Not thread-safe: nothing may render the scene meanwhile. */
RR_API rr_error rr_scene_add_light(rr_scene *scene, const rr_light_info *light);

/* ---- visibility ---------------------------------------------------------- */

typedef enum rr_method {
  RR_METHOD_RC = 0,   /* every sample × every triangle (Durand's loop); tiny scenes only */
  RR_METHOD_RC_BVH,   /* one ray per sample through the BVH */
  RR_METHOD_RC_PACKET,/* coherent packets of rays through the BVH */
  RR_METHOD_2DR_BB,   /* projection, clipping, 2D edge functions over bounding boxes, z-buffer */
  RR_METHOD_2DR_BIN,  /* 2dr-bb with hierarchical binning and early-z */
  RR_METHOD_3DR_BB,   /* 3D edge functions over each triangle's screen bounding box */
  RR_METHOD_3DR_BIN,  /* 3dr-bb with hierarchical binning and early-z */
  RR_METHOD_3DR_FC,   /* 256² frusta, BVH frustum culling, binning at leaves */
  RR_METHOD_3DR_FS,   /* occlusion culling and frustum splitting down to 8², no binning */
  RR_METHOD_3DR_FULL, /* 3dr-fs followed by binning and early-z */
  RR_METHOD_COUNT,
  RR_METHOD_AUTO = 99 /* the fastest for the scene and camera by a cost model (short trials when unsure) */
} rr_method;

/* The method named `name` ("rc", "3dr-bb", ..., "auto"); -1 when unknown. */
RR_API int rr_method_from_name(const char *name);
/* The name of a method ("rc", ...), NULL when out of range. */
RR_API const char *rr_method_name(int method);

/* Anti-aliasing: how shading turns a pixel's visibility samples into colour. The
 * samples themselves are options.samples and options.sample_pos; the modes differ
 * only in shading (rr_shade), never in visibility. */
typedef enum rr_aa_mode {
  RR_AA_NONE = 0, /* no AA mode: every sample shaded, as ssaa (rr_render_options_set_aa's none is one
                     sample at the centre, the image as without AA) */
  RR_AA_SSAA,     /* supersampling: every sample shaded */
  RR_AA_MSAA,     /* multisampling: shaded once per pixel per primitive covering any of its samples,
                     at the mean barycentrics of the covered samples (a point inside the triangle:
                     triangles are convex), the colour shared by the samples it covers */
  RR_AA_CSAA,     /* coverage sampling: visibility at every sample; the first aa_stored samples
                     carry colour as in msaa; every other sample adds its vote (weight 1) to the
                     stored sample nearest to it that saw the same primitive (or the same miss),
                     and to none when no stored sample did */
  RR_AA_MODE_COUNT
} rr_aa_mode;

/* Sample patterns (positions inside the pixel, each in [0, 1)). */
typedef enum rr_aa_pattern {
  RR_AA_STANDARD = 0, /* Direct3D's and Vulkan's standard positions, as offsets from the pixel centre
                         in 1/16 pixel, y down: 1: (0,0); 2: (4,4) (-4,-4); 4: (-2,-6) (6,-2) (-6,2)
                         (2,6); 8: (1,-3) (-1,3) (5,1) (-3,-5) (-5,5) (-7,-1) (3,7) (7,-7); 16: (1,1)
                         (-1,-3) (-3,2) (4,-1) (-5,-2) (2,5) (5,3) (3,-5) (-2,6) (0,-7) (-4,-6) (-6,4)
                         (-8,0) (7,-4) (6,7) (-7,-8) */
  RR_AA_ROTATED,      /* a grid of c × r cells (1×1, 2×1, 2×2, 4×2, 4×4) at the cells' centres, rotated
                         by atan(1/2) about the pixel centre and scaled by √5/2 (offset (u, v) becomes
                         (u - v/2, u/2 + v), so 4 samples are the classic RGSS), wrapped into the pixel */
  RR_AA_JITTER,       /* the same c × r cells, one uniformly random position in each, from a seed */
  RR_AA_PATTERN_COUNT
} rr_aa_pattern;

/* Fills pos[0 .. n-1] with the n positions (n: 1, 2, 4, 8 or 16) of a pattern;
 * seed matters to RR_AA_JITTER alone (the same seed, the same positions). */
RR_API rr_error rr_aa_positions(rr_aa_pattern pattern, int n, uint32_t seed, float pos[][2]);
/* The name of a mode ("none", "ssaa", "msaa", "csaa") or pattern ("standard",
 * "rotated", "jitter"), NULL when out of range. */
RR_API const char *rr_aa_mode_name(int mode);
RR_API const char *rr_aa_pattern_name(int pattern);

typedef struct rr_render_options {
  rr_method method;
  int width, height;  /* image size in pixels */
  int samples;        /* samples per pixel, 1..RR_MAX_SAMPLES (default 1) */
  float sample_pos[RR_MAX_SAMPLES][2]; /* sample s at (x + sample_pos[s][0], y + sample_pos[s][1]) in pixel
                                          (x, y); each in [0, 1) (default: one sample at the centre) */
  int threads;        /* 0: all cores; at most RR_MAX_THREADS */
  rr_aa_mode aa;      /* how shading uses the samples (default RR_AA_NONE); rr_render_options_set_aa
                         sets it with samples and sample_pos */
  int aa_stored;      /* csaa: K, the samples that carry colour: sample_pos[0 .. K-1] (1..samples) */
  int cull_backfaces; /* nonzero: triangles seen from behind are invisible */
  int heat;           /* nonzero: also record E and N charged to each pixel (AOVs evals, nodes) */
  int scalar;         /* nonzero: no SIMD kernels (for comparison; results are the same bits) */
  int frames_hint;    /* auto: how many frames of this view the caller expects (0 or 1: one); a trial
                         of the close candidates runs only when that many frames repay it */
  const char *oracles;/* "key=value,..." overrides of a 3dr method's traversal oracles, or NULL:
                         frustum=N (initial frustum side, 0 = whole image), leaves=0|1
                         (generate samples at BVH leaves or at the root), outside=0|1 (frustum
                         culling), occluded=0|1 (occlusion culling), split=N (split frusta down
                         to N, 0 = never), split-ratio=F, binning=0|1, early-z=0|1, bin=N (top
                         bin side), bin-min=N (bins tested sample by sample) */
} rr_render_options;

/* Fills options with defaults: 3dr-bb, 1024x768, one sample at each pixel's centre,
 * all cores, no culling. */
RR_API void rr_render_options_init(rr_render_options *opt);
/* Sets options.aa, samples, aa_stored and sample_pos for an AA mode: none (samples
 * must be 1: the pixel's centre), ssaa:N and msaa:N (N positions of the pattern),
 * csaa:K/N (stored = K ≤ N): the K stored samples first, at the positions of the
 * pattern of K (where msaa:K samples), then the N - K positions of the pattern of N
 * left after taking, for each stored sample in turn, the one nearest to it (ties: the
 * lower index). N and K are 1, 2, 4, 8 or 16. */
RR_API rr_error rr_render_options_set_aa(rr_device *dev, rr_render_options *opt, rr_aa_mode mode, int samples,
                                         int stored, rr_aa_pattern pattern, uint32_t seed);

typedef struct rr_stats {
  uint64_t setups;     /* S: triangle setups computed */
  uint64_t edge_evals; /* E: one triangle's three edge functions at one sample or bin corner */
  uint64_t nodes;      /* N: BVH nodes visited */
  uint64_t bins;       /* bins that passed binning's coverage test and were refined */
  uint64_t bins_empty; /* of those, bins where the triangle covered no sample */
  double frame_ms;     /* wall time of the visibility pass */
  double cpu_ms;       /* processor time the process spent in it, all threads together */
  int threads;         /* threads the pass ran on */
  int method;          /* the method that ran (what auto chose) */
  char why[256];       /* for auto: why it chose that method ("model: ..." or "trial: ...") */
} rr_stats;

/* Computes primary visibility of a scene from a camera into a new frame. */
RR_API rr_error rr_render(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                          const rr_render_options *opt, rr_frame **out);
/* Releases a frame. */
RR_API void rr_frame_release(rr_frame *frame);
/* The statistics of the pass that made the frame. */
RR_API rr_error rr_frame_get_stats(const rr_frame *frame, rr_stats *stats);
/* Width and height of the frame's visibility buffer. */
RR_API rr_error rr_frame_get_size(const rr_frame *frame, int *width, int *height);
/* Samples per pixel of the frame (options.samples). */
RR_API rr_error rr_frame_get_samples(const rr_frame *frame, int *samples);
/* The frame's sample positions (options.sample_pos): pos[s] for s < samples. */
RR_API rr_error rr_frame_get_sample_pos(const rr_frame *frame, float pos[RR_MAX_SAMPLES][2]);
/* Read-only views of the visibility buffer, row 0 at the top: primitive id
 * (the triangle's id as under "geometries" above, RR_MISS on a miss), ray parameter t along the unnormalised camera ray
 * (+inf on a miss) and barycentrics λ1, λ2 of the hit. With several samples per
 * pixel a pixel's samples lie side by side (height × width × samples, as the
 * sample-* AOVs): sample s of pixel (x, y) at offset (y·width + x)·samples + s. */
RR_API const uint32_t *rr_frame_ids(const rr_frame *frame);
RR_API const float *rr_frame_t(const rr_frame *frame);
RR_API const float *rr_frame_bary1(const rr_frame *frame);
RR_API const float *rr_frame_bary2(const rr_frame *frame);

/* ---- shading and images -------------------------------------------------- */

typedef enum rr_shade_mode {
  RR_SHADE_LAMBERT = 0, /* headlight over the material's base colour */
  RR_SHADE_ID,          /* a stable hashed colour per triangle */
  RR_SHADE_NORMAL,      /* shading normal mapped to colour */
  RR_SHADE_DEPTH,       /* eye distance, near bright, far dark */
  RR_SHADE_HEAT_EVALS,  /* edge evaluations per pixel as a heat map with a legend */
  RR_SHADE_HEAT_NODES,  /* BVH nodes visited per pixel as a heat map with a legend */
  RR_SHADE_LIT,         /* the scene's lights (or a default rig) on its materials, with shadows and
                           mirror reflections: the shading model of docs/shading.md */
  RR_SHADE_COUNT
} rr_shade_mode;

/* The shade mode named `name`; -1 when unknown. */
RR_API int rr_shade_from_name(const char *name);

typedef enum rr_aov {
  RR_AOV_DEPTH = 0, /* 1 float: eye-to-hit distance, +inf on a miss */
  RR_AOV_ID,        /* 1 uint32: primitive id, RR_MISS on a miss */
  RR_AOV_NORMAL,    /* 3 floats: unit shading normal, 0 on a miss */
  RR_AOV_BARY,      /* 2 floats: λ1, λ2, 0 on a miss */
  RR_AOV_EVALS,     /* 1 float: edge evaluations charged to the pixel (needs options.heat) */
  RR_AOV_NODES,     /* 1 float: BVH nodes visited charged to the pixel (needs options.heat) */
  RR_AOV_MESH,      /* 1 uint32: geometry id (segmentation by mesh), RR_MISS on a miss */
  RR_AOV_MATERIAL,  /* 1 uint32: material index (segmentation by material), RR_MISS on a miss */
  RR_AOV_COVERAGE,  /* 1 float: the fraction of the pixel's samples that hit (plain count, no filter) */
  RR_AOV_SAMPLE_ID,    /* N uint32 (N = samples): the id of each sample, channel s = sample s */
  RR_AOV_SAMPLE_DEPTH, /* N floats: the depth of each sample (+inf on a miss) */
  RR_AOV_SAMPLE_MESH,  /* N uint32: the geometry id of each sample */
  RR_AOV_UV,           /* 2 floats: texture coordinates u, v; 0 on a miss or without texture coordinates */
  RR_AOV_UV_DERIV,     /* 4 floats: their derivatives per pixel step du/dx, dv/dx, du/dy, dv/dy (exact,
                          from the camera's ray differentials); 0 where uv is */
  /* The lit mode's parts (docs/shading.md), named as Blender Cycles' passes, with the
   * lights rr_shade_options_init's lit shading uses (the scene's, or the default rig);
   * 0 on a miss. The colour is direct + reflection + emission. */
  RR_AOV_ALBEDO,       /* 3 floats: the diffuse lobe's colour (base colour; × (1 - metallic) for pbr) */
  RR_AOV_DIRECT,       /* 3 floats: light from the lights (shadowed) and the sky on the point itself */
  RR_AOV_REFLECTION,   /* 3 floats: what its mirror reflects, every bounce */
  RR_AOV_SHADOW,       /* 1 float: the fraction of the punctual lights that reach it (facing it, inside
                          its cone, unblocked); 1 when there is none */
  RR_AOV_EMISSION,     /* 3 floats: the radiance it emits */
  RR_AOV_ZDEPTH,       /* 1 float: the hit's distance along the camera's forward axis (the optical axis;
                          depth sensors' convention), +inf on a miss; with several samples the nearest */
  RR_AOV_SHADOW_LIGHTS, /* L floats (L = the punctual lights, 1 .. RR_MAX_SHADOW_LIGHTS): channel i is 1 where
                           light i reaches the point (facing it, inside its cone, unblocked), else 0 (and on a
                           miss): from the same occlusion passes as shadow, which is their mean */
  RR_AOV_INSTANCE,      /* 1 uint32: the instance a sample sees (rr_hit.inst), RR_MISS on a miss and off instances */
  RR_AOV_COUNT
} rr_aov;
#define RR_MAX_SHADOW_LIGHTS 16 /* most lights the shadow-lights AOV holds (a channel each) */
/* With several samples per pixel the per-pixel AOVs follow one rule each: id, mesh,
 * material, instance, normal, bary, uv and uv-deriv are those of the sample nearest the pixel's centre (the
 * lowest such s on a tie; the same s in every pixel), so they belong to one
 * surface; depth is the nearest depth among all the pixel's samples; evals and
 * nodes sum over the samples. The sample-* AOVs give every sample. */

/* The AOV named `name` ("depth", "id", "normal", "bary", "evals", "nodes", "mesh",
 * "material", "coverage", "sample-id", "sample-depth", "sample-mesh", "uv", "uv-deriv",
 * "albedo", "direct", "reflection", "shadow", "emission", "z-depth", "shadow-lights", "instance"); -1 when unknown. */
RR_API int rr_aov_from_name(const char *name);

typedef enum rr_pixel_type { RR_PIXEL_U8 = 0, RR_PIXEL_F32, RR_PIXEL_U32 } rr_pixel_type;

/* What an image holds. It names the image's channels in EXR files and tells the
 * writers whether the values are colour; a zeroed image holds plain values. */
typedef enum rr_image_kind {
  RR_IMAGE_VALUES = 0, /* numbers written as they are; EXR channels Y | R,G | R,G,B | R,G,B,A */
  RR_IMAGE_COLOR,      /* colour: linear light in floats, sRGB-encoded in 8 bits (alpha, the 4th
                          channel, is linear in both); EXR channels as for values. PNG encodes float
                          colour to sRGB, EXR and PFM decode 8-bit colour to linear light */
  RR_IMAGE_AOV         /* RR_IMAGE_AOV + a: AOV a of rr_frame_aov, values as they are, EXR channels
                          depth Z, normal N.X N.Y N.Z, bary bary.u bary.v (λ1, λ2), id, mesh and
                          material (32-bit UINT), evals, nodes, coverage, albedo.R/G/B, direct.R/G/B,
                          reflection.R/G/B, shadow, emission.R/G/B; per sample s (2 digits): id.sNN,
                          Z.sNN, mesh.sNN; uv uv.u uv.v, uv-deriv uvdx.u uvdx.v uvdy.u uvdy.v; z-depth zdepth;
                          per light i (2 digits): shadow.lNN */
} rr_image_kind;

/* An image owned by the caller or by rastray (rr_image_free). */
typedef struct rr_image {
  int width, height, channels;
  rr_pixel_type type;
  void *data; /* row-major, row 0 at the top, channels interleaved */
  int kind;   /* what it holds: an rr_image_kind (RR_IMAGE_AOV + a for AOV a) */
} rr_image;

/* Shades a frame into a new float RGB image of kind RR_IMAGE_COLOR, in linear light:
 * lambert is the lit colour itself; the visualisations (id, normal, depth, heat maps,
 * the background) are display colours stored decoded from sRGB, so that every file
 * shows them as designed: a PNG holds exactly the display values, an EXR the same
 * picture in linear light. The samples are shaded as the frame's AA mode says and
 * their mean taken: rr_shade_frame with the defaults and this mode. */
RR_API rr_error rr_shade(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                         const rr_frame *frame, rr_shade_mode mode, rr_image *out);
/* Resolve filters: how a pixel's colour is made from the samples' colours (in linear
 * light). Each weighs a sample by its offset (dx, dy) from the pixel's centre as
 * f(dx)·f(dy), over |dx|, |dy| < radius, and the weights are normalised per pixel. */
typedef enum rr_filter {
  RR_FILTER_BOX = 0,         /* the mean of the pixel's own samples (radius 0.5) */
  RR_FILTER_MITCHELL,        /* Mitchell–Netravali, B = C = 1/3 (default radius 2): sharper, with
                                negative lobes; results below zero are clamped to zero */
  RR_FILTER_BLACKMAN_HARRIS, /* the 4-term Blackman–Harris window (default radius 1.5): smooth, positive */
  RR_FILTER_COUNT
} rr_filter;

/* The filter named `name` ("box", "mitchell", "blackman-harris"); -1 when unknown. */
RR_API int rr_filter_from_name(const char *name);
/* The name of a filter, NULL when out of range. */
RR_API const char *rr_filter_name(int filter);

#define RR_FILTER_MAX_RADIUS 4.0f /* widest filter radius, in pixels */

/* How a texture is read over a sample's footprint (its pixel's extent in texture
 * space, from exact derivatives of the texture coordinates). */
typedef enum rr_texture_filter {
  RR_TEXTURE_NEAREST = 0, /* the texel under the sample, level 0 (aliases) */
  RR_TEXTURE_BILINEAR,    /* 2×2 texels, level 0 (aliases when minified) */
  RR_TEXTURE_TRILINEAR,   /* bilinear in the two MIP levels around the footprint's size */
  RR_TEXTURE_ANISO,       /* up to `aniso` trilinear probes along the footprint's major axis */
  RR_TEXTURE_EWA,         /* an elliptical weighted average over the footprint (box-like) */
  RR_TEXTURE_FILTER_COUNT
} rr_texture_filter;

/* The texture filter named `name` ("nearest", "bilinear", "trilinear", "aniso", "ewa"); -1 when unknown. */
RR_API int rr_texture_filter_from_name(const char *name);
/* The name of a texture filter, NULL when out of range. */
RR_API const char *rr_texture_filter_name(int filter);

/* How a texture repeats outside [0, 1] (from the material). */
typedef enum rr_texture_wrap {
  RR_WRAP_REPEAT = 0,
  RR_WRAP_CLAMP,  /* clamp to edge */
  RR_WRAP_MIRROR, /* mirrored repeat */
  RR_WRAP_COUNT
} rr_texture_wrap;

/* How the lit shade mode finds which lights a point sees. */
typedef enum rr_shadow_mode {
  RR_SHADOWS_NONE = 0, /* every light reaches every point facing it */
  RR_SHADOWS_RAYS,     /* a shadow ray per point and light through rr_occluded_stream: from a point or spot
                          light to the point offset along its geometric normal (docs/shading.md) */
  RR_SHADOWS_RASTER,   /* the same rays rasterized, the same bits: from a point or spot light (a camera at the
                          light), along a directional light (an orthographic camera) */
  RR_SHADOWS_AUTO,     /* per light and pass: raster for a point or spot light with at least 16384 shadow rays
                          in the pass (docs/shading.md), else rays */
  RR_SHADOWS_COUNT
} rr_shadow_mode;

/* The shadow mode named `name` ("none", "rays", "raster", "auto"); -1 when unknown. */
RR_API int rr_shadows_from_name(const char *name);

#define RR_MAX_DEPTH 16 /* most mirror bounces the lit shade mode follows */

/* How rr_shade_frame shades and resolves a frame. The AA mode (which samples are
 * shaded) is the frame's own, from rr_render_options; these say what is drawn and
 * how the samples' colours become pixels. */
typedef struct rr_shade_options {
  rr_shade_mode mode; /* what to draw (default RR_SHADE_LAMBERT) */
  rr_filter filter;   /* resolve filter (default RR_FILTER_BOX) */
  float radius;       /* in pixels, 0.5 .. RR_FILTER_MAX_RADIUS; 0: the filter's default */
  int alpha;          /* nonzero: a 4th channel, alpha = the filtered coverage of the pixel's samples;
                         the colour is then straight (not premultiplied): the filtered mean of the
                         samples that hit, weighted by their coverage (0 where nothing hit) */
  rr_texture_filter texture_filter; /* default RR_TEXTURE_ANISO */
  int aniso;                        /* most probes of RR_TEXTURE_ANISO, 1 .. 16 (default 16) */
  float lod_bias;                   /* added to the MIP level, in levels (default 0) */
  rr_shadow_mode shadows;           /* lit: how shadows are found (default RR_SHADOWS_RAYS) */
  int max_depth;                    /* lit: most mirror bounces along a path, 0 .. RR_MAX_DEPTH (default 2) */
  int default_lights;               /* lit: nonzero (default): a scene without lights gets the default rig
                                       (a key light with shadows placed from the camera, and a sky) */
  int has_background;               /* nonzero: background is the colour behind misses (default 0: a quiet
                                       grey-blue gradient) */
  float background[3];              /* linear RGB, finite, at least 0 */
  int wave_points;                  /* lit: most points shaded in one wave of passes, counted as every sample
                                       in ssaa and one per pixel in msaa and csaa (whole rows, at least one),
                                       0: RR_LIT_WAVE. Memory grows with it (about 17 bytes a sample, 110 a
                                       shaded point, 90 a ray), the occlusion passes' speed barely beyond
                                       16K rays a light (docs/shading.md); the image does not depend on it */
} rr_shade_options;

#define RR_LIT_WAVE (1 << 18) /* the lit mode's points per wave by default */

/* Fills options with defaults: Lambert, box filter, no alpha, aniso:16 textures. */
RR_API void rr_shade_options_init(rr_shade_options *opt);

/* The statistics of a shading pass. */
typedef struct rr_shade_stats {
  uint64_t shades;   /* shading invocations: one per shaded point of a primitive (the background
                        behind misses is not counted) */
  double shade_ms;   /* wall time turning samples into linear colours (with the box filter of radius
                        0.5 each pixel is resolved as its samples are shaded: that time is here) */
  double resolve_ms; /* wall time of a separate resolve, per-sample colours to pixels (the wide filters;
                        about 0 for the box) */
  uint64_t shadow_rays;        /* lit: shadow rays tested (one per point, light facing it) */
  uint64_t shadow_rays_raster; /* lit: of those, the ones rasterized from their light (--shadows raster, auto) */
  uint64_t reflection_rays;    /* lit: mirror reflection rays traced, all bounces */
  /* lit, wall times of the passes (docs/shading.md); shade_ms holds them */
  double direct_ms;     /* the light passes: each light's shadow rays made, tested, its light added */
  double shadow_ms;     /* of which the occlusion tests (rasterized or traced) */
  double reflection_ms; /* the bounces: reflection rays traced and their hits' surfaces made */
} rr_shade_stats;

/* Shades a frame and resolves its samples to one colour per pixel (opt NULL: the
 * defaults; rr_shade is this with mode alone). The samples are shaded as the frame's
 * AA mode says (options.aa), each in linear light, then filtered. One sample per
 * pixel and the box filter give one shade per pixel, as is. Heat maps are per pixel:
 * neither filtered nor given alpha. stats, when not NULL, receives the pass's
 * statistics. */
RR_API rr_error rr_shade_frame(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                               const rr_frame *frame, const rr_shade_options *opt, rr_image *out,
                               rr_shade_stats *stats);
/* Extracts an AOV of a frame into a new image of kind RR_IMAGE_AOV + aov. */
RR_API rr_error rr_frame_aov(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                             const rr_frame *frame, rr_aov aov, rr_image *out);
/* rr_shade_frame with opt->mode RR_SHADE_LIT, and from the same passes the lit
 * AOVs whose bit (1u << aov, aov in RR_AOV_ALBEDO .. RR_AOV_EMISSION or
 * RR_AOV_SHADOW_LIGHTS, which fails when there is no punctual light or more than
 * RR_MAX_SHADOW_LIGHTS) is set in
 * `aovs`, each into a new image aov_images[aov] (the other entries untouched), as
 * rr_frame_aov makes them but under opt's lights and shadow mode: the parts of the
 * point shaded for each pixel's sample nearest its centre (in msaa and csaa the
 * point of that sample's primitive in the pixel). With one sample per pixel they
 * equal rr_frame_aov's bit for bit, whatever opt->shadows. On failure no image is made. */
RR_API rr_error rr_shade_frame_aovs(rr_device *dev, const rr_scene *scene, const rr_camera *cam,
                                    const rr_frame *frame, const rr_shade_options *opt, unsigned aovs,
                                    rr_image aov_images[RR_AOV_COUNT], rr_image *out, rr_shade_stats *stats);
/* Frees the pixels of an image made by rastray. */
RR_API void rr_image_free(rr_image *img);

/* ---- image files ----------------------------------------------------------- */
/* A path's format is its extension (.png, .pfm, .exr, .npy) or a prefix naming it
 * ("exr:PATH", "png:-"); the prefix wins. "-" is standard output. Standard output and
 * other files that are not regular files (/dev/null, a FIFO) may go without either:
 * they take PNG for colour and 8-bit images, EXR for several layers, NPY otherwise.
 * PNG holds 1, 3 or 4 channels of 8 bits; PFM 1 or 3 floats (ids only when exact as
 * floats); NPY any image as it is; EXR any image, floats as FLOAT, ids as UINT. */

typedef struct rr_output rr_output; /* image files written all or nothing */

/* Creates an empty output set; its failures are reported in dev. */
RR_API rr_error rr_output_new(rr_device *dev, rr_output **out);
/* Encodes n images as the file `path`: one image, or n > 1 images of one size as the
 * layers of one EXR (no two may share a channel name). A regular file (new or
 * replaced) is written at once under a unique temporary name in its directory
 * (path.tmp.XXXXXX); standard output and other non-regular files are kept in memory.
 * Nothing appears at path before rr_output_commit. At most one output of a set may
 * be standard output. A failed add adds nothing; the images may be freed after it. */
RR_API rr_error rr_output_add(rr_output *set, const rr_image *images, int n, const char *path);
/* Adds a file of the caller's bytes (a JSON sidecar, a report) to the set, written
 * like an image's: path is taken as it is (no format prefix; "-" is standard output). */
RR_API rr_error rr_output_add_bytes(rr_output *set, const void *data, size_t size, const char *path);
/* Makes the set's outputs appear: renames every temporary over its target (when
 * one rename fails, the files renamed before it are removed again), then writes
 * the non-regular targets, standard output last. Once the files are in place, a
 * failure writing a stream leaves them. A set is committed once. */
RR_API rr_error rr_output_commit(rr_output *set);
/* Releases a set, removing the temporaries of a set not committed. */
RR_API void rr_output_release(rr_output *set);

/* Writes one image: an output set of one file. */
RR_API rr_error rr_image_write(rr_device *dev, const rr_image *img, const char *path);
/* Writes n images of one size as the layers of one EXR file (an output set of one). */
RR_API rr_error rr_image_write_layers(rr_device *dev, const rr_image *images, int n, const char *path);
/* Reads an image written by rr_image_write (.png, .pfm, .exr, .npy); an EXR of at most
 * 4 channels of one type, its kind found from their names (R, G, B, A: colour). Other
 * files give plain values. */
RR_API rr_error rr_image_read(rr_device *dev, const char *path, rr_image *out);


/* ---- scene files ------------------------------------------------------------ */
/* A JSON file that composes a scene: meshes (files or built-ins) with transforms and
 * material overrides, lights, a camera and render settings (docs/scene-file.md). */

typedef struct rr_load_options {
  const char *base_dir; /* where the file's relative paths start; NULL: the scene file's directory */
  int sandbox;          /* nonzero: refuse every path (after symbolic links) outside base_dir, and
                           built-ins that read files (grid:); default 0 */
  int builtins;         /* nonzero (default): meshes may be built-in names ("builtin": "sphere:32") */
  uint64_t max_tris;    /* most triangles the scene may reserve, meshes together; 0 (default): no limit */
} rr_load_options;

/* Fills load options with defaults: paths from the scene file's directory, no
 * sandbox, built-ins allowed, no triangle limit. */
RR_API void rr_load_options_init(rr_load_options *opt);

/* Which fields of rr_scene_settings a scene file gave (rr_scene_settings.given). */
enum {
  RR_SETTING_SIZE = 1u << 0,           /* render.width, render.height */
  RR_SETTING_METHOD = 1u << 1,         /* render.method */
  RR_SETTING_AA = 1u << 2,             /* render.aa, samples, aa_stored, sample_pos */
  RR_SETTING_CULL = 1u << 3,           /* render.cull_backfaces */
  RR_SETTING_SHADE = 1u << 4,          /* shade.mode */
  RR_SETTING_SHADOWS = 1u << 5,        /* shade.shadows */
  RR_SETTING_MAX_DEPTH = 1u << 6,      /* shade.max_depth */
  RR_SETTING_FILTER = 1u << 7,         /* shade.filter, shade.radius */
  RR_SETTING_TEXTURE_FILTER = 1u << 8, /* shade.texture_filter, shade.aniso */
  RR_SETTING_LOD_BIAS = 1u << 9,       /* shade.lod_bias */
  RR_SETTING_ALPHA = 1u << 10,         /* shade.alpha */
  RR_SETTING_DEFAULT_LIGHTS = 1u << 11, /* shade.default_lights */
  RR_SETTING_BACKGROUND = 1u << 12      /* shade.has_background, shade.background */
};
/* Which fields of an rr_camera a camera file or a scene file's camera gave. */
enum {
  RR_CAMERA_FIELD_TYPE = 1u << 0,
  RR_CAMERA_FIELD_EYE = 1u << 1,
  RR_CAMERA_FIELD_TARGET = 1u << 2,
  RR_CAMERA_FIELD_UP = 1u << 3,
  RR_CAMERA_FIELD_FOV = 1u << 4,
  RR_CAMERA_FIELD_ORTHO = 1u << 5,
  RR_CAMERA_FIELD_LENS = 1u << 6 /* intrinsics and distortion (opencv cameras) */
};

/* What a scene file says about rendering it. Fields the file does not give keep
 * the defaults of rr_render_options_init and rr_shade_options_init, except that
 * the method is RR_METHOD_AUTO and the shade mode RR_SHADE_LIT (as the command line's). */
typedef struct rr_scene_settings {
  unsigned given;           /* RR_SETTING_* bits */
  unsigned camera_given;    /* RR_CAMERA_FIELD_* bits; 0: the file has no camera */
  rr_camera camera;         /* rr_camera_init's where the file gives nothing */
  rr_render_options render; /* oracles is always NULL */
  rr_shade_options shade;
} rr_scene_settings;

/* Loads a scene file (opt NULL: defaults) into a new committed scene; settings, when
 * not NULL, receives its camera and render settings. Nothing is made on failure:
 * the message names the file and the key ("scene file 'a.json': 'meshes[1].scale':
 * expected a number"). rr_scene_load reads a ".json" path this way too. */
RR_API rr_error rr_scene_load_file(rr_device *dev, const char *path, const rr_load_options *opt, rr_scene **out,
                                   rr_scene_settings *settings);
/* Reads a camera file ({"eye", "target", "up", "fov", "type", "ortho_height"}, or a
 * 4x4 camera-to-world "matrix"; docs/scene-file.md) into *cam: the fields it gives
 * change, the others stay; *fields (may be NULL) receives their RR_CAMERA_FIELD_* bits. */
RR_API rr_error rr_camera_load(rr_device *dev, const char *path, rr_camera *cam, unsigned *fields);

/* A camera of a reconstruction tool's file, with the image it belongs to. */
typedef struct rr_imported_camera {
  rr_camera camera; /* opencv, or opencv-fisheye for COLMAP's fisheye models and nerfstudio's OPENCV_FISHEYE */
  int width, height; /* the image's size in pixels */
  char name[256];    /* COLMAP: the image's NAME; NeRF: the frame's file_path (else its index) */
} rr_imported_camera;
/* Reads the cameras of a COLMAP text model (path: the directory holding cameras.txt
 * and images.txt, or either file; models SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL,
 * RADIAL, OPENCV, FULL_OPENCV, OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE;
 * COLMAP's pixel centres at +0.5 become OpenCV's at 0) or of a NeRF transforms .json
 * (camera_angle_x/y or fl_x/fl_y, cx/cy (default w/2, h/2), k1 k2 p1 p2 k3 (k1..k4 with
 * nerfstudio's "camera_model": "OPENCV_FISHEYE"), w and h, per-frame overrides, and
 * each frame's camera-to-world transform_matrix in OpenGL's axes). select: one image
 * by its name (file_path), else by its 0-based index in the file; NULL: all of them.
 * Fills out[0 .. min(n, cap) - 1] in the file's order and *count (may be NULL) = n,
 * the images selected (1 with select). cap 0 counts only. The whole file is checked:
 * a malformed one fails with one line naming the file and the line (or JSON key). */
RR_API rr_error rr_camera_import(rr_device *dev, const char *path, const char *select, rr_imported_camera *out,
                                 int cap, int *count);

#ifdef __cplusplus
}
#endif
#endif
