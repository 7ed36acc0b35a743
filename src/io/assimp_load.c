/* Scene import through assimp's C API: every format assimp reads.
 *
 * Polygons are fan-triangulated here rather than by assimp, so primitive ids follow
 * the documented order: meshes in node order (file order), faces in file order,
 * face k of n corners giving triangles (0, j, j+1). Each node/mesh pair is one
 * geometry, named after its node (an OBJ object or group, a glTF node), else after
 * its mesh; assimp splits an OBJ object by material into meshes of one node. */
#include "io/io.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static vec3 xform_point(const struct aiMatrix4x4 *m, struct aiVector3D v) {
  return v3(m->a1 * v.x + m->a2 * v.y + m->a3 * v.z + m->a4,
            m->b1 * v.x + m->b2 * v.y + m->b3 * v.z + m->b4,
            m->c1 * v.x + m->c2 * v.y + m->c3 * v.z + m->c4);
}

static vec3 xform_normal(const struct aiMatrix4x4 *m, struct aiVector3D v) {
  return v3_norm(v3(m->a1 * v.x + m->a2 * v.y + m->a3 * v.z,
                    m->b1 * v.x + m->b2 * v.y + m->b3 * v.z,
                    m->c1 * v.x + m->c2 * v.y + m->c3 * v.z));
}

static bool is_identity(const struct aiMatrix4x4 *m) {
  return m->a1 == 1 && m->b2 == 1 && m->c3 == 1 && m->d4 == 1 && m->a2 == 0 && m->a3 == 0 &&
         m->a4 == 0 && m->b1 == 0 && m->b3 == 0 && m->b4 == 0 && m->c1 == 0 && m->c2 == 0 &&
         m->c4 == 0 && m->d1 == 0 && m->d2 == 0 && m->d3 == 0;
}

static rr_error add_mesh(rr_scene *s, const struct aiNode *node, const struct aiMesh *mesh,
                         const struct aiMatrix4x4 *m, uint32_t mat_base) {
  uint64_t ntri = 0;
  for (unsigned f = 0; f < mesh->mNumFaces; f++)
    if (mesh->mFaces[f].mNumIndices >= 3) ntri += mesh->mFaces[f].mNumIndices - 2;
  if (ntri > UINT32_MAX) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "mesh too large");
  bool has_n = mesh->mNormals != NULL, has_uv = mesh->mTextureCoords[0] != NULL;
  uint32_t mat = mat_base + mesh->mMaterialIndex;
  const char *name = node->mName.length ? node->mName.data : mesh->mName.data;
  rr_error e = rr_scene_reserve(s, (uint32_t)ntri, has_n, has_uv);
  if (!e) e = rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, name);
  if (e) return e;
  bool ident = is_identity(m);
  for (unsigned f = 0; f < mesh->mNumFaces; f++) {
    const struct aiFace *face = &mesh->mFaces[f];
    for (unsigned j = 1; j + 1 < face->mNumIndices; j++) {
      unsigned corner[3] = {face->mIndices[0], face->mIndices[j], face->mIndices[j + 1]};
      vec3 p[3], n[3];
      float uv[3][2];
      for (int k = 0; k < 3; k++) {
        unsigned v = corner[k];
        if (v >= mesh->mNumVertices)
          return rr_fail(s->dev, RR_ERROR_PARSE, "face %u of mesh '%s' has vertex index %u out of range",
                         f, mesh->mName.data, v);
        struct aiVector3D q = mesh->mVertices[v];
        p[k] = ident ? v3(q.x, q.y, q.z) : xform_point(m, q);
        if (has_n) {
          struct aiVector3D nn = mesh->mNormals[v];
          n[k] = ident ? v3(nn.x, nn.y, nn.z) : xform_normal(m, nn);
        }
        if (has_uv) {
          uv[k][0] = mesh->mTextureCoords[0][v].x;
          uv[k][1] = mesh->mTextureCoords[0][v].y;
        }
      }
      rr_scene_push(s, p, has_n ? n : NULL, has_uv ? (const float(*)[2])uv : NULL, mat);
    }
  }
  return RR_OK;
}

static struct aiMatrix4x4 mat_mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b) {
  const float *x = &a->a1, *y = &b->a1;
  struct aiMatrix4x4 r;
  float *o = &r.a1;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      o[4 * i + j] = x[4 * i] * y[j] + x[4 * i + 1] * y[4 + j] + x[4 * i + 2] * y[8 + j] + x[4 * i + 3] * y[12 + j];
  return r;
}

static rr_error add_node(rr_scene *s, const struct aiScene *sc, const struct aiNode *node,
                         const struct aiMatrix4x4 *parent, uint32_t mat_base, int depth) {
  if (depth > 256) return rr_fail(s->dev, RR_ERROR_PARSE, "scene graph deeper than 256 levels");
  struct aiMatrix4x4 m = mat_mul(parent, &node->mTransformation);
  for (unsigned i = 0; i < node->mNumMeshes; i++) {
    if (node->mMeshes[i] >= sc->mNumMeshes) return rr_fail(s->dev, RR_ERROR_PARSE, "node names a missing mesh");
    rr_error e = add_mesh(s, node, sc->mMeshes[node->mMeshes[i]], &m, mat_base);
    if (e) return e;
  }
  for (unsigned c = 0; c < node->mNumChildren; c++) {
    rr_error e = add_node(s, sc, node->mChildren[c], &m, mat_base, depth + 1);
    if (e) return e;
  }
  return RR_OK;
}

static rr_error add_materials(rr_scene *s, const struct aiScene *sc) {
  for (unsigned i = 0; i < sc->mNumMaterials; i++) {
    const struct aiMaterial *am = sc->mMaterials[i];
    struct aiColor4D c = {SCENE_GREY, SCENE_GREY, SCENE_GREY, 1.0f};
    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &c);
    struct aiString tex;
    tex.length = 0;
    bool has_tex = aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL,
                                        NULL, NULL) == AI_SUCCESS && tex.length > 0;
    float rgb[3] = {c.r, c.g, c.b};
    /* A textured material's texture carries the colour; OBJ files often leave Kd at 0. */
    if (has_tex && rgb[0] + rgb[1] + rgb[2] == 0) rgb[0] = rgb[1] = rgb[2] = 1;
    if (rr_scene_add_material(s, rgb, has_tex ? tex.data : NULL) == UINT32_MAX)
      return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding materials");
  }
  return RR_OK;
}

rr_error rr_scene_load_file(rr_scene *s, const char *path) {
  struct stat st;
  if (stat(path, &st) != 0)
    return rr_fail(s->dev, RR_ERROR_IO, "cannot open scene '%s': %s", path, strerror(errno));
  if (!S_ISREG(st.st_mode)) return rr_fail(s->dev, RR_ERROR_IO, "cannot open scene '%s': not a regular file", path);
  FILE *f = fopen(path, "rb");
  if (!f) return rr_fail(s->dev, RR_ERROR_IO, "cannot open scene '%s': %s", path, strerror(errno));
  fclose(f);

  const struct aiScene *sc = aiImportFile(path, aiProcess_ValidateDataStructure);
  if (!sc) {
    const char *why = aiGetErrorString();
    char line[256];
    snprintf(line, sizeof line, "%s", why && *why ? why : "unknown error");
    for (char *c = line; *c; c++)
      if (*c == '\n' || *c == '\r') *c = ' ';
    return rr_fail(s->dev, RR_ERROR_PARSE, "cannot read scene '%s': %s", path, line);
  }
  uint32_t mat_base = s->nmaterials;
  rr_error e = add_materials(s, sc);
  struct aiMatrix4x4 id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (!e && sc->mRootNode) e = add_node(s, sc, sc->mRootNode, &id, mat_base, 0);
  aiReleaseImport(sc);
  if (e) return e;

  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = 0;
  else strcpy(dir, ".");
  rr_scene_load_textures(s, dir);
  return RR_OK;
}
