import numpy as np
import rastray

v = np.array([[-1, -1, 4], [1, -1, 4], [0, 1, 4]], np.float32)  # one triangle, 4 m ahead
f = np.array([[0, 1, 2]], np.uint32)
K = np.array([[300, 0, 159.5], [0, 300, 119.5], [0, 0, 1]])
with rastray.Scene.from_arrays(v, f) as scene:
    cam = rastray.Camera.opencv(K, dist=[-0.1, 0.01, 0, 0], R=np.eye(3), t=np.zeros(3))
    out = scene.render(cam, size=(320, 240), aovs=("z-depth", "id", "normal", "mesh"))
    print(out["z-depth"][120, 160], (out["id"] != rastray.MISS).sum(), "pixels hit")
    hits = scene.intersect(np.array([[0, 0, 0, 0, 0, 1]], np.float32))  # rays (N, 6): origin, direction
    print(hits["t_hit"], hits["primitive_ids"], hits["primitive_normals"])
