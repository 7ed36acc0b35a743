/* Scene import: polygons fan-triangulated in file order, negative OBJ indices,
 * PLY and glTF files, materials with textures, and every bad input. */
#include "vis/vis.h"
#include "io/io.h"
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

static char dir[] = "/tmp/rr_loader_XXXXXX";

static bool vertex_is(const rr_scene *s, int k, uint32_t i, float x, float y, float z) {
  vec3 p = scene_vertex(s, k, i);
  return p.x == x && p.y == y && p.z == z;
}

int main(void) {
  if (!mkdtemp(dir)) return 1;
  rr_device *dev = rr_device_new();
  rr_scene *s = NULL;

  /* A quad and a pentagon: 2 + 3 triangles, fans (0, j, j+1) in file order. */
  const char *obj = test_write_file(dir, "poly.obj",
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 2 0\nv 2 1 0\n"
                               "f 1 2 3 4\nf 5 6 7 8 9\n");
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->ntris == 5, "quad + pentagon give %u triangles", s->ntris);
    CHECK(vertex_is(s, 0, 0, 0, 0, 0) && vertex_is(s, 1, 0, 1, 0, 0) && vertex_is(s, 2, 0, 1, 1, 0), "triangle 0 = 1 2 3");
    CHECK(vertex_is(s, 0, 1, 0, 0, 0) && vertex_is(s, 1, 1, 1, 1, 0) && vertex_is(s, 2, 1, 0, 1, 0), "triangle 1 = 1 3 4");
    CHECK(vertex_is(s, 0, 4, 2, 0, 0) && vertex_is(s, 1, 4, 2.5f, 2, 0) && vertex_is(s, 2, 4, 2, 1, 0),
          "triangle 4 = 5 8 9");
    rr_scene_release(s);
  }

  /* Negative (relative) indices. */
  obj = test_write_file(dir, "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1\nf -4 -3 -1\n");
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->ntris == 2, "negative indices: %u triangles", s->ntris);
    CHECK(vertex_is(s, 2, 1, 0, 0, 1), "-1 is the latest vertex");
    rr_scene_release(s);
  }

  /* Materials: a base colour and a texture path from an MTL file. */
  test_write_file(dir, "m.mtl", "newmtl red\nKd 0.9 0.1 0.1\nnewmtl tex\nKd 1 1 1\nmap_Kd missing.png\n");
  obj = test_write_file(dir, "mat.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                              "usemtl red\nf 1/1 2/2 3/3\nusemtl tex\nf 1/1 3/3 2/2\n");
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    bool red = false, tex = false;
    for (uint32_t m = 0; m < s->nmaterials; m++) {
      red |= fabsf(s->materials[m].color[0] - 0.9f) < 1e-6f && fabsf(s->materials[m].color[1] - 0.1f) < 1e-6f;
      tex |= s->materials[m].texture_path && strstr(s->materials[m].texture_path, "missing.png");
    }
    CHECK(red && tex, "materials: red base colour %d, texture path %d", red, tex);
    CHECK(s->uv[0][0] != NULL, "uvs kept");
    CHECK(s->ntris == 2 && s->materials[s->material[0]].color[0] > 0.8f, "triangle 0 is red");
    rr_scene_release(s);
  }

  /* PLY (ASCII) with a quad. */
  const char *ply = test_write_file(dir, "q.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                        "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  CHECK(rr_scene_load(dev, ply, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->ntris == 2, "PLY quad: %u triangles", s->ntris);
    rr_scene_release(s);
  }

  /* glTF 2.0 with an embedded buffer: one triangle, translated by its node. */
  const char *gltf = test_write_file(dir, 
      "t.gltf",
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0,\"translation\":[0,0,5]}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
      "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,"
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
      "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
      "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}");
  CHECK(rr_scene_load(dev, gltf, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->ntris == 1, "glTF: %u triangles", s->ntris);
    CHECK(vertex_is(s, 1, 0, 1, 0, 5), "node translation applied");
    rr_scene_release(s);
  }

  /* Bad input: each fails with its code and a message naming the problem. */
  struct {
    const char *path, *text;
    rr_error code;
    const char *needle;
  } bad[] = {
      {"/nonexistent/x.obj", NULL, RR_ERROR_IO, "/nonexistent/x.obj"},
      {"garbage.xyz", "\x01\x02 not a scene", RR_ERROR_PARSE, "garbage.xyz"},
      {"empty.obj", "# a polyline, no faces\nv 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n", RR_ERROR_EMPTY, "no triangles"},
      {"tiny.obj", "#\n", RR_ERROR_PARSE, "tiny.obj"},
      {"degenerate.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\n", RR_ERROR_EMPTY, "degenerate"},
      {"nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", RR_ERROR_EMPTY, "no triangles"},
      {"badply.ply", "ply\nformat ascii 1.0\nelement vertex 99\nend_header\n1 2\n", RR_ERROR_PARSE, "badply.ply"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    const char *p = bad[i].text ? test_write_file(dir, bad[i].path, bad[i].text) : bad[i].path;
    s = NULL;
    rr_error e = rr_scene_load(dev, p, &s);
    CHECK(e == bad[i].code && s == NULL, "%s: code %d (expected %d): %s", bad[i].path, e, bad[i].code,
          rr_device_message(dev));
    CHECK(strstr(rr_device_message(dev), bad[i].needle) && !strchr(rr_device_message(dev), '\n'),
          "%s: message '%s' should name '%s' on one line", bad[i].path, rr_device_message(dev), bad[i].needle);
    rr_scene_release(s);
  }
  CHECK(rr_scene_load(dev, dir, &s) == RR_ERROR_IO, "a directory is not a scene");

  /* Degenerate and non-finite triangles are skipped and counted, not fatal. */
  obj = test_write_file(dir, "mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv inf 0 0\nf 1 2 3\nf 1 2 4\nf 1 2 5\n");
  CHECK(rr_scene_load(dev, obj, &s) == RR_OK, "%s", rr_device_message(dev));
  if (s) {
    CHECK(s->ntris == 1 && s->skipped == 2, "mixed: %u kept, %llu skipped", s->ntris, (unsigned long long)s->skipped);
    rr_scene_release(s);
  }

  /* The API path for meshes made in memory. */
  CHECK(rr_scene_new(dev, &s) == RR_OK, "new");
  float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t idx[] = {0, 1, 2, 0, 1, 7};
  CHECK(rr_scene_add_mesh(s, pos, 3, idx, 1, NULL) == RR_OK, "add mesh");
  CHECK(rr_scene_add_mesh(s, pos, 3, idx, 2, NULL) == RR_ERROR_ARGUMENT, "index out of range rejected");
  rr_scene_release(s);

  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  CHECK(system(cmd) == 0, "cleanup");
  rr_device_release(dev);
  return test_done();
}
