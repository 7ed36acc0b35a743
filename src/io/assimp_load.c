/* Scene import through assimp's C API: every format assimp reads.
 *
 * Polygons are fan-triangulated here rather than by assimp, so primitive ids follow
 * the documented order: meshes in node order (file order), faces in file order,
 * face k of n corners giving triangles (0, j, j+1), each counted whether kept or
 * dropped as degenerate (the scene keeps dropped faces' ids). Each node/mesh pair is one
 * geometry, named after its node (an OBJ object or group, a glTF node), else after
 * its mesh; assimp splits an OBJ object by material into meshes of one node.
 * Besides triangles the file gives materials (with embedded textures), vertex
 * colours, cameras, lights and its up axis. */
#include "core/color.h"
#include "io/import_guard.h"
#include "shade/texture.h"

#include <assimp/ObjMaterial.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* What the loader needs to know about the file beyond assimp's scene. */
typedef struct file_kind {
  bool gltf;           /* glTF/GLB: linear vertex colours, cameras with a vertical fov */
  bool colors_srgb;    /* vertex colours are display-encoded (every format but glTF) */
} file_kind;

static vec3 xform_point(const struct aiMatrix4x4 *m, struct aiVector3D v) {
  return v3(m->a1 * v.x + m->a2 * v.y + m->a3 * v.z + m->a4,
            m->b1 * v.x + m->b2 * v.y + m->b3 * v.z + m->b4,
            m->c1 * v.x + m->c2 * v.y + m->c3 * v.z + m->c4);
}

static vec3 xform_dir(const struct aiMatrix4x4 *m, struct aiVector3D v) {
  return v3(m->a1 * v.x + m->a2 * v.y + m->a3 * v.z, m->b1 * v.x + m->b2 * v.y + m->b3 * v.z,
            m->c1 * v.x + m->c2 * v.y + m->c3 * v.z);
}

/* The determinant of m's upper 3×3: negative for a mirroring transform. */
static float det3(const struct aiMatrix4x4 *m) {
  return v3_dot(v3(m->a1, m->a2, m->a3), v3_cross(v3(m->b1, m->b2, m->b3), v3(m->c1, m->c2, m->c3)));
}

/* The normal matrix of m: its upper 3×3's inverse transpose M⁻ᵀ = C / det, where the
 * rows of the cofactor matrix C are the cross products of M's other two rows. C
 * times the sign of det keeps normals on their side under mirroring transforms and
 * divides by no tiny det (normals are renormalised). Rows of 3, row-major. */
static void normal_matrix(const struct aiMatrix4x4 *m, float out[9]) {
  vec3 r0 = v3(m->a1, m->a2, m->a3), r1 = v3(m->b1, m->b2, m->b3), r2 = v3(m->c1, m->c2, m->c3);
  float sign = det3(m) < 0 ? -1.0f : 1.0f;
  v3_store(out, v3_scale(v3_cross(r1, r2), sign));
  v3_store(out + 3, v3_scale(v3_cross(r2, r0), sign));
  v3_store(out + 6, v3_scale(v3_cross(r0, r1), sign));
}

static vec3 xform_normal(const float nm[9], struct aiVector3D v) {
  return v3_norm(v3(nm[0] * v.x + nm[1] * v.y + nm[2] * v.z, nm[3] * v.x + nm[4] * v.y + nm[5] * v.z,
                    nm[6] * v.x + nm[7] * v.y + nm[8] * v.z));
}

static bool is_identity(const struct aiMatrix4x4 *m) {
  return m->a1 == 1 && m->b2 == 1 && m->c3 == 1 && m->d4 == 1 && m->a2 == 0 && m->a3 == 0 &&
         m->a4 == 0 && m->b1 == 0 && m->b3 == 0 && m->b4 == 0 && m->c1 == 0 && m->c2 == 0 &&
         m->c4 == 0 && m->d1 == 0 && m->d2 == 0 && m->d3 == 0;
}

static rr_error add_mesh(rr_scene *s, const struct aiNode *node, const struct aiMesh *mesh,
                         const struct aiMatrix4x4 *m, uint32_t mat_base, const file_kind *kind) {
  uint64_t ntri = 0;
  for (unsigned f = 0; f < mesh->mNumFaces; f++)
    if (mesh->mFaces[f].mNumIndices >= 3) ntri += mesh->mFaces[f].mNumIndices - 2;
  if (ntri > UINT32_MAX) return rr_fail(s->dev, RR_ERROR_ARGUMENT, "mesh too large");
  bool has_n = mesh->mNormals != NULL, has_uv = mesh->mTextureCoords[0] != NULL, has_col = mesh->mColors[0] != NULL;
  uint32_t mat = mat_base + mesh->mMaterialIndex;
  const char *name = node->mName.length ? node->mName.data : mesh->mName.data;
  rr_error e = rr_scene_reserve(s, (uint32_t)ntri, has_n, has_uv);
  if (!e && has_col) e = rr_scene_reserve_colors(s);
  if (!e) e = rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat, name);
  if (e) return e;
  bool ident = is_identity(m);
  float nm[9];
  normal_matrix(m, nm);
  /* A mirroring transform (det < 0) turns the winding around: swapping two corners
   * keeps the triangles' front faces where the file has them. */
  bool mirrored = det3(m) < 0;
  for (unsigned f = 0; f < mesh->mNumFaces; f++) {
    const struct aiFace *face = &mesh->mFaces[f];
    for (unsigned j = 1; j + 1 < face->mNumIndices; j++) {
      unsigned corner[3] = {face->mIndices[0], face->mIndices[mirrored ? j + 1 : j], face->mIndices[mirrored ? j : j + 1]};
      vec3 p[3], n[3], col[3];
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
          n[k] = ident ? v3(nn.x, nn.y, nn.z) : xform_normal(nm, nn);
        }
        if (has_uv) {
          uv[k][0] = mesh->mTextureCoords[0][v].x;
          uv[k][1] = mesh->mTextureCoords[0][v].y;
        }
        if (has_col) {
          struct aiColor4D c = mesh->mColors[0][v];
          col[k] = kind->colors_srgb ? v3(srgb_decode(c.r), srgb_decode(c.g), srgb_decode(c.b))
                                     : v3(c.r, c.g, c.b);
        }
      }
      rr_scene_push_inf(s, p, 0, has_n ? n : NULL, has_uv ? (const float(*)[2])uv : NULL, has_col ? col : NULL, mat);
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

static const struct aiMatrix4x4 identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static rr_error add_node(rr_scene *s, const struct aiScene *sc, const struct aiNode *node,
                         const struct aiMatrix4x4 *parent, uint32_t mat_base, const file_kind *kind, int depth) {
  if (depth > 256) return rr_fail(s->dev, RR_ERROR_PARSE, "scene graph deeper than 256 levels");
  struct aiMatrix4x4 m = mat_mul(parent, &node->mTransformation);
  for (unsigned i = 0; i < node->mNumMeshes; i++) {
    if (node->mMeshes[i] >= sc->mNumMeshes) return rr_fail(s->dev, RR_ERROR_PARSE, "node names a missing mesh");
    rr_error e = add_mesh(s, node, sc->mMeshes[node->mMeshes[i]], &m, mat_base, kind);
    if (e) return e;
  }
  for (unsigned c = 0; c < node->mNumChildren; c++) {
    rr_error e = add_node(s, sc, node->mChildren[c], &m, mat_base, kind, depth + 1);
    if (e) return e;
  }
  return RR_OK;
}

/* The world transform of the node named `name` (cameras and lights are placed by
 * the node of their name); false when there is none. */
static bool node_xform(const struct aiNode *node, const char *name, const struct aiMatrix4x4 *parent,
                       struct aiMatrix4x4 *out, int depth) {
  if (!node || depth > 256) return false;
  struct aiMatrix4x4 m = mat_mul(parent, &node->mTransformation);
  if (strcmp(node->mName.data, name) == 0) return *out = m, true;
  for (unsigned c = 0; c < node->mNumChildren; c++)
    if (node_xform(node->mChildren[c], name, &m, out, depth + 1)) return true;
  return false;
}

static struct aiMatrix4x4 placement(const struct aiScene *sc, const struct aiString *name) {
  struct aiMatrix4x4 m = identity;
  node_xform(sc->mRootNode, name->data, &identity, &m, 0);
  return m;
}

static rr_error add_cameras(rr_scene *s, const struct aiScene *sc, const file_kind *kind) {
  for (unsigned i = 0; i < sc->mNumCameras; i++) {
    const struct aiCamera *ac = sc->mCameras[i];
    struct aiMatrix4x4 m = placement(sc, &ac->mName);
    /* assimp 5.2's glTF importer copies the node's translation into mPosition,
     * which the node's transform then applies again (assimp issue 5054); a glTF
     * camera sits at its node's origin. */
    struct aiVector3D pos = kind->gltf ? (struct aiVector3D){0, 0, 0} : ac->mPosition;
    vec3 fwd = v3_norm(xform_dir(&m, ac->mLookAt)), up = xform_dir(&m, ac->mUp);
    up = v3_norm(v3_sub(up, v3_scale(fwd, v3_dot(up, fwd))));
    float fov = ac->mHorizontalFOV;
    if (kind->gltf && ac->mAspect > 0) {
      /* glTF keeps its vertical yfov; assimp turned it into a horizontal one: before
       * 5.3 as yfov · aspect, since as 2 atan(aspect · tan(yfov / 2)) (assimp issue 4435) */
      bool old = aiGetVersionMajor() < 5 || (aiGetVersionMajor() == 5 && aiGetVersionMinor() < 3);
      fov = old ? fov / ac->mAspect : 2.0f * atanf(tanf(0.5f * fov) / ac->mAspect);
    }
    file_camera c = {.eye = xform_point(&m, pos), .fwd = fwd, .up = up, .fov = fov,
                      .fov_vertical = kind->gltf, .ortho_width = 2 * ac->mOrthographicWidth};
    rr_error e = rr_scene_add_camera(s, ac->mName.data, &c);
    if (e) return e;
  }
  return RR_OK;
}

static rr_error add_lights(rr_scene *s, const struct aiScene *sc) {
  for (unsigned i = 0; i < sc->mNumLights; i++) {
    const struct aiLight *al = sc->mLights[i];
    struct aiMatrix4x4 m = placement(sc, &al->mName);
    float deg = 180.0f / (float)RR_PI;
    rr_light_info l = {.name = al->mName.data,
                       .type = al->mType >= aiLightSource_DIRECTIONAL && al->mType <= aiLightSource_AREA
                                   ? (rr_light_type)al->mType : RR_LIGHT_UNDEFINED,
                       .color = {al->mColorDiffuse.r, al->mColorDiffuse.g, al->mColorDiffuse.b},
                       .attenuation = {al->mAttenuationConstant, al->mAttenuationLinear, al->mAttenuationQuadratic},
                       .inner_cone_deg = al->mAngleInnerCone * deg,
                       .outer_cone_deg = al->mAngleOuterCone * deg,
                       .size = {al->mSize.x, al->mSize.y}};
    v3_store(l.position, xform_point(&m, al->mPosition));
    v3_store(l.direction, v3_norm(xform_dir(&m, al->mDirection)));
    rr_error e = rr_scene_append_light(s, &l);
    if (e) return e;
  }
  return RR_OK;
}

/* The embedded texture a material names: "*N" (the N-th), else one whose file name
 * matches (FBX, ZAE, .blend keep names); assimp's C++ GetEmbeddedTexture, which the
 * C API lacks. NULL when none. */
static const struct aiTexture *embedded_texture(const struct aiScene *sc, const char *name) {
  if (name[0] == '*') {
    char *end;
    unsigned long i = strtoul(name + 1, &end, 10);
    return !*end && end != name + 1 && i < sc->mNumTextures ? sc->mTextures[i] : NULL;
  }
  const char *base = name;
  for (const char *p = name; *p; p++)
    if (*p == '/' || *p == '\\') base = p + 1;
  for (unsigned i = 0; i < sc->mNumTextures; i++) {
    const char *f = sc->mTextures[i]->mFilename.data, *fb = f;
    for (const char *p = f; *p; p++)
      if (*p == '/' || *p == '\\') fb = p + 1;
    if (*fb && strcasecmp(fb, base) == 0) return sc->mTextures[i];
  }
  return NULL;
}

/* Decodes an embedded texture: compressed bytes (mHeight 0, mWidth bytes of PNG,
 * JPEG...) or mWidth × mHeight BGRA texels. */
static bool decode_embedded(rr_texture *t, const struct aiTexture *at) {
  if (!at->pcData) return false;
  if (at->mHeight == 0) return rr_texture_decode(t, at->pcData, at->mWidth);
  if (at->mWidth > RR_MAX_SIZE || at->mHeight > RR_MAX_SIZE) return false;
  size_t n = (size_t)at->mWidth * at->mHeight;
  bool opaque = true;
  for (size_t k = 0; k < n; k++) opaque &= at->pcData[k].a == 255;
  uint8_t *rgb = malloc(3 * n), *alpha = opaque ? NULL : malloc(n);
  if (!rgb || (!opaque && !alpha)) return free(rgb), free(alpha), false;
  for (size_t k = 0; k < n; k++) {
    rgb[3 * k] = at->pcData[k].r, rgb[3 * k + 1] = at->pcData[k].g, rgb[3 * k + 2] = at->pcData[k].b;
    if (alpha) alpha[k] = at->pcData[k].a;
  }
  t->width = (int)at->mWidth, t->height = (int)at->mHeight, t->rgb = rgb, t->alpha = alpha;
  if (rr_texture_prepare(t)) return true;
  rr_texture_clear(t);
  return false;
}

static void get_rgb(const struct aiMaterial *am, const char *key, unsigned type, unsigned index, float rgb[3]) {
  struct aiColor4D c;
  if (aiGetMaterialColor(am, key, type, index, &c) == AI_SUCCESS) rgb[0] = c.r, rgb[1] = c.g, rgb[2] = c.b;
}

static void get_float(const struct aiMaterial *am, const char *key, unsigned type, unsigned index, float *v) {
  ai_real f;
  unsigned one = 1;
  if (aiGetMaterialFloatArray(am, key, type, index, &f, &one) == AI_SUCCESS && one == 1 && isfinite(f)) *v = (float)f;
}

/* The shading model's inputs (rr_material_params) of a material and the names of
 * the textures shading does not use yet. glTF's metallic–roughness comes through
 * assimp's PBR keys; MTL's Ks, Ns, Ka, Ke, d (Tr: assimp gives 1 - Tr as the
 * opacity) and illum through the classic ones. */
static rr_error read_params(rr_material *mt, const struct aiMaterial *am, bool gltf) {
  rr_material_params *p = &mt->params;
  p->model = gltf ? RR_MATERIAL_PBR : RR_MATERIAL_PHONG;
  get_rgb(am, AI_MATKEY_COLOR_SPECULAR, p->specular);
  get_rgb(am, AI_MATKEY_COLOR_AMBIENT, p->ambient);
  get_rgb(am, AI_MATKEY_COLOR_EMISSIVE, p->emission);
  get_float(am, AI_MATKEY_SHININESS, &p->shininess);
  p->shininess = fminf(fmaxf(p->shininess, 0.0f), 10000.0f);
  get_float(am, AI_MATKEY_OPACITY, &p->opacity);
  int illum;
  unsigned one = 1;
  if (aiGetMaterialIntegerArray(am, AI_MATKEY_OBJ_ILLUM, &illum, &one) == AI_SUCCESS && one == 1) p->illum = illum;
  if (gltf) {
    struct aiColor4D base;
    if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &base) == AI_SUCCESS) {
      mt->color[0] = base.r, mt->color[1] = base.g, mt->color[2] = base.b;
      p->opacity = base.a;
    }
    get_float(am, AI_MATKEY_METALLIC_FACTOR, &p->metallic);
    get_float(am, AI_MATKEY_ROUGHNESS_FACTOR, &p->roughness);
    p->metallic = fminf(fmaxf(p->metallic, 0.0f), 1.0f), p->roughness = fminf(fmaxf(p->roughness, 0.0f), 1.0f);
  }
  static const struct {
    enum aiTextureType type;
    rr_material_map map;
  } maps[] = {{aiTextureType_SPECULAR, RR_MAP_SPECULAR},   {aiTextureType_NORMALS, RR_MAP_NORMAL},
              {aiTextureType_HEIGHT, RR_MAP_NORMAL},       {aiTextureType_LIGHTMAP, RR_MAP_OCCLUSION},
              {aiTextureType_AMBIENT_OCCLUSION, RR_MAP_OCCLUSION}, {aiTextureType_EMISSIVE, RR_MAP_EMISSIVE},
              {aiTextureType_UNKNOWN, RR_MAP_METALLIC_ROUGHNESS}, {aiTextureType_DIFFUSE_ROUGHNESS, RR_MAP_METALLIC_ROUGHNESS}};
  for (size_t k = 0; k < sizeof maps / sizeof *maps; k++) {
    struct aiString tex;
    tex.length = 0;
    if (mt->maps[maps[k].map] || aiGetMaterialTexture(am, maps[k].type, 0, &tex, NULL, NULL, NULL, NULL, NULL, NULL) != AI_SUCCESS ||
        !tex.length)
      continue;
    char *name = malloc(tex.length + 1);
    if (!name) return RR_ERROR_MEMORY;
    memcpy(name, tex.data, tex.length + 1);
    mt->maps[maps[k].map] = name;
  }
  return RR_OK;
}

static rr_error add_materials(rr_scene *s, const struct aiScene *sc, bool gltf) {
  for (unsigned i = 0; i < sc->mNumMaterials; i++) {
    const struct aiMaterial *am = sc->mMaterials[i];
    struct aiColor4D c = {SCENE_GREY, SCENE_GREY, SCENE_GREY, 1.0f};
    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &c);
    struct aiString tex, name;
    tex.length = name.length = 0;
    enum aiTextureMapMode wrap[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
    bool has_tex = aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL,
                                        wrap, NULL) == AI_SUCCESS && tex.length > 0;
    bool named = aiGetMaterialString(am, AI_MATKEY_NAME, &name) == AI_SUCCESS;
    float rgb[3] = {c.r, c.g, c.b};
    /* A textured material's texture carries the colour; OBJ files often leave Kd at 0. */
    if (has_tex && rgb[0] + rgb[1] + rgb[2] == 0) rgb[0] = rgb[1] = rgb[2] = 1;
    uint32_t m = rr_scene_add_material(s, rgb, has_tex ? tex.data : NULL);
    if (m == UINT32_MAX) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding materials");
    rr_error e = rr_scene_name_material(s, m, named ? name.data : NULL);
    if (e) return e;
    /* An embedded texture is read now, while assimp holds it; files come later. */
    const struct aiTexture *at = has_tex ? embedded_texture(sc, tex.data) : NULL;
    rr_material *mt = &s->materials[m];
    if (read_params(mt, am, gltf)) return rr_fail(s->dev, RR_ERROR_MEMORY, "out of memory adding materials");
    /* glTF samplers' wrapS/wrapT and MTL's -clamp arrive as assimp's map modes (decal: clamped too) */
    for (int k = 0; k < 2; k++)
      mt->texture.wrap[k] = wrap[k] == aiTextureMapMode_Mirror ? RR_WRAP_MIRROR
                            : wrap[k] == aiTextureMapMode_Clamp || wrap[k] == aiTextureMapMode_Decal ? RR_WRAP_CLAMP
                                                                                                        : RR_WRAP_REPEAT;
    if (at) mt->texture_status = decode_embedded(&mt->texture, at) ? RR_TEXTURE_EMBEDDED : RR_TEXTURE_UNREADABLE;
    else if (has_tex && tex.data[0] == '*') mt->texture_status = RR_TEXTURE_MISSING; /* no such embedded one */
  }
  return RR_OK;
}

/* An integer of the file's metadata (FBX's UpAxis...), false when absent. */
static bool meta_int(const struct aiScene *sc, const char *key, int *out) {
  const struct aiMetadata *md = sc->mMetaData;
  for (unsigned i = 0; md && i < md->mNumProperties; i++) {
    if (strcmp(md->mKeys[i].data, key) != 0 || !md->mValues[i].mData) continue;
    if (md->mValues[i].mType == AI_INT32) return *out = *(const int32_t *)md->mValues[i].mData, true;
    if (md->mValues[i].mType == AI_UINT64) return *out = (int)*(const uint64_t *)md->mValues[i].mData, true;
  }
  return false;
}

static vec3 axis_vec(int axis, int sign) {
  float v[3] = {0, 0, 0};
  v[axis] = sign < 0 ? -1.0f : 1.0f;
  return v3_load(v);
}

/* The model's up and front. Files that record their axes in metadata (FBX:
 * UpAxis/UpAxisSign, FrontAxis/FrontAxisSign; assimp leaves the data as it is)
 * say so; assimp already turns COLLADA's Z_UP, 3DS and MD5 to Y-up (checked on
 * files: a rotation on the root node) and glTF is Y-up by its specification.
 * Blender's .blend and STL (3D printing) are Z-up by convention, and assimp keeps
 * them so; their front is -Y (Blender's front view looks from -Y). Everything else:
 * Y up, front +Z (the viewer of a Y-up file at +Z looking towards -Z). */
static void set_axes(rr_scene *s, const struct aiScene *sc, const char *ext) {
  int up = 1, up_sign = 1, front = 2, front_sign = 1;
  if (ext && (strcasecmp(ext, "blend") == 0 || strcasecmp(ext, "stl") == 0)) up = 2, front = 1, front_sign = -1;
  if (meta_int(sc, "UpAxis", &up) && up >= 0 && up <= 2) {
    meta_int(sc, "UpAxisSign", &up_sign);
    /* a front along the up axis (or none) gives way to the usual one for that up axis */
    if (!meta_int(sc, "FrontAxis", &front) || front == up || front < 0 || front > 2)
      front = up == 2 ? 1 : 2, front_sign = up == 2 ? -1 : 1;
    else meta_int(sc, "FrontAxisSign", &front_sign);
  }
  if (up < 0 || up > 2) up = 1;
  s->up = axis_vec(up, up_sign);
  s->front = axis_vec(front, front_sign);
}

rr_error rr_scene_import_file(rr_scene *s, const char *path) {
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
  const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
  const char *ext = dot && (!slash || dot > slash) ? dot + 1 : NULL;
  bool gltf = ext && (strcasecmp(ext, "gltf") == 0 || strcasecmp(ext, "glb") == 0);
  /* glTF's COLOR_0 is linear by its specification; the other formats leave it
   * unsaid and their writers (PLY and OBJ from scanners and MeshLab, Blender's FBX
   * default) store display (sRGB) values. */
  file_kind kind = {.gltf = gltf, .colors_srgb = !gltf};
  uint32_t mat_base = s->nmaterials;
  rr_error e = add_materials(s, sc, gltf);
  if (!e && sc->mRootNode) e = add_node(s, sc, sc->mRootNode, &identity, mat_base, &kind, 0);
  if (!e) e = add_cameras(s, sc, &kind);
  if (!e) e = add_lights(s, sc);
  if (!e) set_axes(s, sc, ext);
  aiReleaseImport(sc);
  if (e) return e;

  char dir[4096];
  snprintf(dir, sizeof dir, "%s", path);
  char *cut = strrchr(dir, '/');
  if (cut) *cut = 0;
  else strcpy(dir, ".");
  rr_scene_load_textures(s, dir);
  return RR_OK;
}
