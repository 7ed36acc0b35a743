/* rr_scene_import_guarded: import that cannot take the process down.
 *
 * assimp crashes, loops and allocates without bound on small malformed files. So
 * a file is first held against its declared counts (import_check.c), then
 * imported in a forked child under a memory limit (RLIMIT_AS: what the child
 * already maps plus max_memory) and a time limit (the parent waits on a pipe
 * and kills the child when the time is up). The child runs the whole in-process
 * loader (rr_scene_import_file: assimp, materials, embedded and file textures,
 * cameras, lights, axes) into a scene of its own and writes that scene into a
 * memfd; the parent appends it to its scene by the same calls a loader makes
 * (rr_scene_add_material, rr_scene_open_geometry, rr_scene_push_inf...), so
 * everything the loader supports comes through unchanged, ids and dropped faces
 * included. Handing back the finished scene rather than assimp's needs no second
 * import in the parent and no copy of assimp's data structures. A crash, a
 * timeout or running out of memory becomes RR_ERROR_PARSE or RR_ERROR_MEMORY with
 * a message naming the file and the cause; the child's own output (assimp's
 * log lines, a C++ runtime's last words) goes to /dev/null unless importer_log.
 * The child leaves with _exit: the parent's atexit handlers (temporary files)
 * and stdio buffers are the parent's. */
#define _GNU_SOURCE /* memfd_create, strsignal */
#include "io/import_guard.h"
#include "shade/texture.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

void rr_import_limits_init(rr_import_limits *lim) {
  if (!lim) return;
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  *lim = (rr_import_limits){.timeout_s = 60,
                            .max_memory = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page / 2 : 0};
}

rr_error rr_device_set_import_limits(rr_device *dev, const rr_import_limits *lim) {
  if (!dev || !lim) return rr_fail(dev, RR_ERROR_ARGUMENT, "rr_device_set_import_limits: NULL argument");
  if (!(lim->timeout_s >= 0) || !isfinite(lim->timeout_s))
    return rr_fail(dev, RR_ERROR_ARGUMENT, "import timeout %g: expected a finite number of seconds, at least 0",
                   lim->timeout_s);
  dev->import = *lim;
  dev->import_set = true;
  return rr_ok(dev);
}

void rr_device_set_import_test_hook(rr_device *dev, import_test_hook hook) { dev->import_hook = (int)hook; }

/* ---- the scene image the child writes and the parent reads ------------------------- */

#define IMAGE_MAGIC 0x31637372u /* "rsc1" */
enum { HAS_N = 1, HAS_UV = 2, HAS_COL = 4, HAS_IDS = 8 };

typedef struct writer {
  FILE *f;
  bool bad;
} writer;

static void put(writer *w, const void *p, size_t n) {
  if (n && fwrite(p, 1, n, w->f) != n) w->bad = true;
}
static void put_u32(writer *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_str(writer *w, const char *s) {
  uint32_t n = s ? (uint32_t)strlen(s) : UINT32_MAX;
  put_u32(w, n);
  if (s) put(w, s, n);
}
static void put_vec(writer *w, vec3 v) {
  float f[3];
  v3_store(f, v);
  put(w, f, sizeof f);
}

/* Writes scene c to fd; false when it could not (out of memory or space). */
static bool write_scene(const rr_scene *c, int fd) {
  writer w = {fdopen(fd, "wb"), false};
  if (!w.f) return false;
  put_u32(&w, IMAGE_MAGIC);
  put_u32(&w, c->nmaterials);
  for (uint32_t m = 0; m < c->nmaterials; m++) {
    const rr_material *mt = &c->materials[m];
    put_str(&w, mt->name);
    put(&w, mt->color, sizeof mt->color);
    put_str(&w, mt->texture_path);
    put(&w, &mt->texture_status, sizeof mt->texture_status);
    put(&w, &mt->params, sizeof mt->params);
    put(&w, mt->texture.wrap, sizeof mt->texture.wrap);
    bool texels = mt->texture.rgb && mt->texture.width > 0 && mt->texture.height > 0;
    put_u32(&w, texels ? (uint32_t)mt->texture.width : 0);
    put_u32(&w, texels ? (uint32_t)mt->texture.height : 0);
    size_t texel_count = texels ? (size_t)mt->texture.width * (size_t)mt->texture.height : 0;
    if (texels) put(&w, mt->texture.rgb, texel_count * 3);
    put_u32(&w, texels && mt->texture.alpha);
    if (texels && mt->texture.alpha) put(&w, mt->texture.alpha, texel_count);
    for (int k = 0; k < RR_MAP_COUNT; k++) put_str(&w, mt->maps[k]);
  }
  unsigned flags = (c->n[0][0] ? HAS_N : 0) | (c->uv[0][0] ? HAS_UV : 0) | (c->col[0][0] ? HAS_COL : 0) |
                   (c->file_id ? HAS_IDS : 0);
  put_u32(&w, c->ntris);
  put(&w, &c->skipped, sizeof c->skipped);
  put_u32(&w, flags);
  size_t n = c->ntris;
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < 3; a++) {
      put(&w, c->p[k][a], 4 * n);
      if (flags & HAS_N) put(&w, c->n[k][a], 4 * n);
      if (flags & HAS_COL) put(&w, c->col[k][a], 4 * n);
      if (a < 2 && (flags & HAS_UV)) put(&w, c->uv[k][a], 4 * n);
    }
  if (flags & HAS_IDS) put(&w, c->file_id, 4 * n);
  put_u32(&w, c->ngeoms);
  for (uint32_t g = 0; g < c->ngeoms; g++) {
    const scene_geometry *ge = &c->geoms[g];
    put_u32(&w, ge->first), put_u32(&w, ge->face), put_u32(&w, ge->material), put_u32(&w, (uint32_t)ge->kind);
    put_str(&w, ge->name == NO_NAME ? NULL : c->names + ge->name);
  }
  put_u32(&w, c->ncameras);
  for (uint32_t i = 0; i < c->ncameras; i++) {
    const file_camera *cam = &c->cameras[i];
    put_str(&w, cam->name);
    put_vec(&w, cam->eye), put_vec(&w, cam->fwd), put_vec(&w, cam->up);
    put(&w, &cam->fov, sizeof cam->fov), put(&w, &cam->fov_vertical, sizeof cam->fov_vertical);
    put(&w, &cam->ortho_width, sizeof cam->ortho_width);
  }
  put_u32(&w, c->nlights);
  for (uint32_t i = 0; i < c->nlights; i++) {
    rr_light_info l = c->lights[i];
    put_str(&w, l.name);
    l.name = NULL;
    put(&w, &l, sizeof l);
  }
  put_vec(&w, c->up), put_vec(&w, c->front);
  put_u32(&w, IMAGE_MAGIC);
  bool ok = fclose(w.f) == 0 && !w.bad;
  return ok;
}

typedef struct reader {
  const uint8_t *p;
  size_t n, pos;
  bool bad;
} reader;

/* The next n bytes (NULL past the end: the reader turns bad). */
static const uint8_t *get_span(reader *r, uint64_t n) {
  if (r->bad || n > r->n - r->pos) return r->bad = true, NULL;
  const uint8_t *q = r->p + r->pos;
  r->pos += (size_t)n;
  return q;
}
static void get(reader *r, void *dst, size_t n) {
  const uint8_t *q = get_span(r, n);
  if (q) memcpy(dst, q, n);
  else memset(dst, 0, n);
}
static uint32_t get_u32(reader *r) {
  uint32_t v;
  get(r, &v, sizeof v);
  return v;
}
/* A string as a malloc'd copy (NULL for none; *nomem set when out of memory). */
static char *get_str(reader *r, bool *nomem) {
  uint32_t n = get_u32(r);
  const uint8_t *q = n == UINT32_MAX ? NULL : get_span(r, n);
  if (!q) return NULL;
  char *s = malloc((size_t)n + 1);
  if (!s) return *nomem = true, NULL;
  memcpy(s, q, n);
  s[n] = 0;
  return s;
}
static vec3 get_vec(reader *r) {
  float f[3];
  get(r, f, sizeof f);
  return v3(f[0], f[1], f[2]);
}
static float get_f(const uint8_t *a, size_t i) {
  float v;
  memcpy(&v, a + 4 * i, 4);
  return v;
}

/* Appends the materials of the image; false when out of memory. */
static bool read_materials(rr_scene *s, reader *r) {
  uint32_t nmat = get_u32(r);
  for (uint32_t m = 0; m < nmat && !r->bad; m++) {
    bool nomem = false;
    char *name = get_str(r, &nomem);
    float color[3];
    get(r, color, sizeof color);
    char *tex_path = get_str(r, &nomem);
    uint32_t id = nomem ? UINT32_MAX : rr_scene_add_material(s, color, tex_path);
    free(tex_path);
    if (id == UINT32_MAX) {
      free(name);
      return false;
    }
    rr_material *mt = &s->materials[id];
    mt->name = name;
    get(r, &mt->texture_status, sizeof mt->texture_status);
    get(r, &mt->params, sizeof mt->params);
    get(r, mt->texture.wrap, sizeof mt->texture.wrap);
    uint32_t w = get_u32(r), h = get_u32(r);
    if (w > RR_MAX_SIZE || h > RR_MAX_SIZE) r->bad = true;
    const uint8_t *texels = w && h ? get_span(r, (uint64_t)w * h * 3) : NULL;
    const uint8_t *alpha = get_u32(r) && texels ? get_span(r, (uint64_t)w * h) : NULL;
    if (texels) { /* level 0 as the child read it; the MIP chain is rebuilt here, not sent */
      if (!(mt->texture.rgb = malloc((size_t)w * h * 3))) return false;
      memcpy(mt->texture.rgb, texels, (size_t)w * h * 3);
      mt->texture.width = (int)w, mt->texture.height = (int)h;
      if (alpha) {
        if (!(mt->texture.alpha = malloc((size_t)w * h))) return false;
        memcpy(mt->texture.alpha, alpha, (size_t)w * h);
      }
      if (!rr_texture_prepare(&mt->texture)) return false;
    }
    for (int k = 0; k < RR_MAP_COUNT; k++) mt->maps[k] = get_str(r, &nomem);
    if (nomem) return false;
  }
  return true;
}

/* Appends the image's triangles and geometries, its dropped faces counted where
 * they fall (the child's ids become the parent's, offset by the faces before). */
static rr_error read_triangles(rr_scene *s, reader *r, uint32_t mat_base, uint32_t nmat) {
  uint32_t ntris = get_u32(r);
  uint64_t skipped;
  get(r, &skipped, sizeof skipped);
  unsigned flags = get_u32(r);
  const uint8_t *p[3][3], *n[3][3] = {{0}}, *col[3][3] = {{0}}, *uv[3][2] = {{0}}, *ids = NULL;
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < 3; a++) {
      p[k][a] = get_span(r, 4ull * ntris);
      if (flags & HAS_N) n[k][a] = get_span(r, 4ull * ntris);
      if (flags & HAS_COL) col[k][a] = get_span(r, 4ull * ntris);
      if (a < 2 && (flags & HAS_UV)) uv[k][a] = get_span(r, 4ull * ntris);
    }
  if (flags & HAS_IDS) ids = get_span(r, 4ull * ntris);
  uint32_t ngeoms = get_u32(r);
  if (r->bad) return RR_ERROR_PARSE;
  rr_error e = rr_scene_reserve(s, ntris, flags & HAS_N, flags & HAS_UV);
  if (!e && (flags & HAS_COL)) e = rr_scene_reserve_colors(s);
  uint64_t faces = (uint64_t)ntris + skipped, done = 0; /* the child's faces, and those appended */
  for (uint32_t g = 0; g < ngeoms && !e; g++) {
    uint32_t first = get_u32(r), face = get_u32(r), mat = get_u32(r), kind = get_u32(r);
    bool nomem = false;
    char *name = get_str(r, &nomem);
    /* the next geometry's first: where this one ends */
    size_t at = r->pos;
    uint32_t end = ntris;
    if (g + 1 < ngeoms) {
      end = get_u32(r);
      r->pos = at;
    }
    if (r->bad || face < done || face > faces || mat >= nmat || kind != RR_GEOMETRY_TRIANGLE || first > end ||
        end > ntris)
      e = RR_ERROR_PARSE;
    if (!e && nomem) e = RR_ERROR_MEMORY;
    if (!e) {
      s->skipped += face - done, done = face;
      e = rr_scene_open_geometry(s, RR_GEOMETRY_TRIANGLE, mat_base + mat, name);
    }
    free(name);
    for (uint32_t i = first; i < end && !e; i++) {
      uint32_t id32 = i;
      if (ids) memcpy(&id32, ids + 4 * (size_t)i, 4);
      uint64_t id = id32;
      if (id < done || id >= faces) {
        e = RR_ERROR_PARSE;
        break;
      }
      s->skipped += id - done, done = id + 1;
      vec3 pk[3], nk[3], ck[3];
      float uk[3][2];
      for (int k = 0; k < 3; k++) {
        pk[k] = v3(get_f(p[k][0], i), get_f(p[k][1], i), get_f(p[k][2], i));
        if (flags & HAS_N) nk[k] = v3(get_f(n[k][0], i), get_f(n[k][1], i), get_f(n[k][2], i));
        if (flags & HAS_COL) ck[k] = v3(get_f(col[k][0], i), get_f(col[k][1], i), get_f(col[k][2], i));
        if (flags & HAS_UV) uk[k][0] = get_f(uv[k][0], i), uk[k][1] = get_f(uv[k][1], i);
      }
      uint64_t before = s->skipped;
      if (!rr_scene_push_inf(s, pk, 0, flags & HAS_N ? nk : NULL, flags & HAS_UV ? (const float(*)[2])uk : NULL,
                             flags & HAS_COL ? ck : NULL, mat_base + mat) &&
          s->skipped == before)
        e = RR_ERROR_MEMORY; /* not dropped (the child kept it), so out of memory */
    }
  }
  if (!e && (r->bad || done > faces)) e = RR_ERROR_PARSE;
  if (!e) s->skipped += faces - done;
  return e;
}

/* Appends the scene image the child wrote to s. */
static rr_error read_scene(rr_scene *s, const char *path, const uint8_t *data, size_t size) {
  reader r = {data, size, 0, false};
  rr_error e = get_u32(&r) == IMAGE_MAGIC ? RR_OK : RR_ERROR_PARSE;
  uint32_t mat_base = s->nmaterials;
  if (!e && !read_materials(s, &r)) e = RR_ERROR_MEMORY;
  if (!e && r.bad) e = RR_ERROR_PARSE;
  if (!e) e = read_triangles(s, &r, mat_base, s->nmaterials - mat_base);
  uint32_t ncam = e ? 0 : get_u32(&r);
  for (uint32_t i = 0; i < ncam && !e && !r.bad; i++) {
    bool nomem = false;
    char *name = get_str(&r, &nomem);
    file_camera c = {0};
    c.eye = get_vec(&r), c.fwd = get_vec(&r), c.up = get_vec(&r);
    get(&r, &c.fov, sizeof c.fov), get(&r, &c.fov_vertical, sizeof c.fov_vertical);
    get(&r, &c.ortho_width, sizeof c.ortho_width);
    e = nomem ? RR_ERROR_MEMORY : r.bad ? RR_ERROR_PARSE : rr_scene_add_camera(s, name, &c);
    free(name);
  }
  uint32_t nlights = e ? 0 : get_u32(&r);
  for (uint32_t i = 0; i < nlights && !e && !r.bad; i++) {
    bool nomem = false;
    char *name = get_str(&r, &nomem);
    rr_light_info l;
    get(&r, &l, sizeof l);
    l.name = name;
    e = nomem ? RR_ERROR_MEMORY : r.bad ? RR_ERROR_PARSE : rr_scene_append_light(s, &l);
    free(name);
  }
  if (!e) {
    vec3 up = get_vec(&r), front = get_vec(&r);
    if (get_u32(&r) != IMAGE_MAGIC || r.bad) e = RR_ERROR_PARSE;
    else s->up = up, s->front = front;
  }
  if (e == RR_ERROR_ARGUMENT) return e; /* the scene's own refusal (a triangle budget), already said */
  if (e == RR_ERROR_MEMORY) return rr_fail(s->dev, e, "cannot read scene '%s': out of memory", path);
  if (e) return rr_fail(s->dev, e, "cannot read scene '%s': the import process handed back a damaged scene", path);
  return RR_OK;
}

/* ---- the child ------------------------------------------------------------------------ */

/* The bytes of address space the process maps now (0 when unknown). */
static uint64_t mapped_bytes(void) {
  FILE *f = fopen("/proc/self/statm", "r");
  unsigned long long pages = 0;
  if (f) {
    if (fscanf(f, "%llu", &pages) != 1) pages = 0;
    fclose(f);
  }
  long page = sysconf(_SC_PAGESIZE);
  return page > 0 ? pages * (uint64_t)page : 0;
}

static void send_message(int fd, rr_error code, const char *msg) {
  char buf[600];
  int n = snprintf(buf, sizeof buf, "%d %s", (int)code, msg);
  if (n > (int)sizeof buf - 1) n = (int)sizeof buf - 1;
  for (int done = 0; done < n;) {
    ssize_t w = write(fd, buf + done, (size_t)(n - done));
    if (w <= 0 && errno != EINTR) break;
    if (w > 0) done += (int)w;
  }
}

static void child_main(rr_device *dev, const char *path, const rr_import_limits *lim, int memfd, int msgfd,
                       pid_t parent) {
  /* the caller's signal handling (a thread waiting for SIGINT...) is not here: die by them */
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, NULL);
  const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGALRM};
  for (size_t i = 0; i < sizeof sigs / sizeof *sigs; i++) signal(sigs[i], SIG_DFL);
#ifdef __linux__
  prctl(PR_SET_PDEATHSIG, SIGKILL); /* the parent gone, nobody waits for the import */
#endif
  if (getppid() != parent) _exit(127);
  /* a fork in another thread between its pipe() and its close() of the write end
   * copies that end here: closed, so that its parent sees its own child end */
  DIR *fds = opendir("/proc/self/fd");
  for (struct dirent *d; fds && (d = readdir(fds));) {
    int fd = atoi(d->d_name);
    if (fd > STDERR_FILENO && fd != memfd && fd != msgfd && fd != dirfd(fds)) close(fd);
  }
  if (fds) closedir(fds);
  struct rlimit no_core = {0, 0};
  setrlimit(RLIMIT_CORE, &no_core); /* a crash leaves no core file in the working directory */
  if (lim->max_memory) {
    struct rlimit as;
    uint64_t want = mapped_bytes() + lim->max_memory;
    if (want < lim->max_memory) want = UINT64_MAX;
    if (getrlimit(RLIMIT_AS, &as) == 0) {
      as.rlim_cur = as.rlim_max != RLIM_INFINITY && want > as.rlim_max ? as.rlim_max : (rlim_t)want;
      setrlimit(RLIMIT_AS, &as);
    }
  }
  int null = open("/dev/null", O_WRONLY);
  if (null >= 0) {
    dup2(lim->importer_log ? STDERR_FILENO : null, STDOUT_FILENO); /* never into an image on stdout */
    if (!lim->importer_log) dup2(null, STDERR_FILENO);
  }
  if (dev->import_hook == IMPORT_HOOK_CRASH) {
    signal(SIGSEGV, SIG_DFL); /* past any sanitizer's handler: the parent sees the signal */
    raise(SIGSEGV);
  }
  /* The caller's progress function is the parent's: it may take locks another of
   * the parent's threads held at the fork. */
  dev->progress = NULL;
  rr_scene *c;
  rr_error e = rr_scene_new(dev, &c);
  if (!e) e = rr_scene_import_file(c, path);
  if (!e && !write_scene(c, memfd))
    e = rr_fail(dev, RR_ERROR_MEMORY, "cannot read scene '%s': out of memory handing the scene back", path);
  if (e) {
    const char *msg = rr_device_message(dev);
    char oom[400];
    if (e == RR_ERROR_MEMORY || strstr(msg, "bad_alloc") || strstr(msg, "Cannot allocate memory")) {
      snprintf(oom, sizeof oom, "cannot read scene '%s': out of memory (the import may use %.0f MiB; see --max-memory)",
               path, lim->max_memory / 1048576.0);
      msg = oom, e = RR_ERROR_MEMORY;
    }
    send_message(msgfd, e, msg);
  }
  _exit(e ? 1 : 0);
}

/* ---- the parent --------------------------------------------------------------------- */

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* A memory file for the child's scene (a deleted temporary where memfd is missing). */
static int memory_file(void) {
#ifdef __linux__
  int fd = memfd_create("rastray-import", MFD_CLOEXEC);
  if (fd >= 0) return fd;
#endif
  FILE *f = tmpfile();
  int fd2 = f ? dup(fileno(f)) : -1;
  if (f) fclose(f);
  return fd2;
}

static rr_error import_guarded(rr_scene *s, const char *path, const rr_import_limits *lim) {
  rr_device *dev = s->dev;
  int memfd = memory_file(), pipefd[2] = {-1, -1};
  if (memfd < 0 || pipe(pipefd) != 0) {
    int err = errno;
    if (memfd >= 0) close(memfd);
    return rr_fail(dev, RR_ERROR_IO, "cannot read scene '%s': cannot start the import process: %s", path, strerror(err));
  }
  fcntl(pipefd[0], F_SETFD, FD_CLOEXEC), fcntl(pipefd[1], F_SETFD, FD_CLOEXEC);
  pid_t parent = getpid(), pid = fork();
  if (pid == 0) {
    close(pipefd[0]);
    child_main(dev, path, lim, memfd, pipefd[1], parent);
  }
  int fork_err = errno;
  close(pipefd[1]);
  if (pid < 0) {
    close(pipefd[0]), close(memfd);
    return rr_fail(dev, RR_ERROR_IO, "cannot read scene '%s': cannot start the import process: %s", path,
                   strerror(fork_err));
  }
  /* the child's message, until it closes the pipe by ending, or the time is up */
  char msg[640];
  size_t got = 0;
  bool timed_out = false;
  double deadline = now_s() + lim->timeout_s;
  for (;;) {
    int wait_ms = -1;
    if (lim->timeout_s > 0) {
      double left = deadline - now_s();
      if (left <= 0) {
        timed_out = true;
        break;
      }
      wait_ms = left > 1e6 ? 1000000000 : (int)ceil(left * 1e3);
    }
    struct pollfd pfd = {pipefd[0], POLLIN, 0};
    int ready = poll(&pfd, 1, wait_ms);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue; /* the deadline check above decides */
    if (ready < 0) break;
    char buf[256];
    ssize_t n = read(pipefd[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    size_t keep = (size_t)n < sizeof msg - 1 - got ? (size_t)n : sizeof msg - 1 - got;
    memcpy(msg + got, buf, keep);
    got += keep;
  }
  msg[got] = 0;
  for (char *c = msg; *c; c++) /* one line, whatever the child sent */
    if (*c == '\n' || *c == '\r') *c = ' ';
  close(pipefd[0]);
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  rr_error e = RR_OK;
  if (timed_out)
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read scene '%s': the import took longer than %g s (see --import-timeout)",
                path, lim->timeout_s);
  else if (WIFSIGNALED(status))
    e = rr_fail(dev, RR_ERROR_PARSE, "cannot read scene '%s': the importer crashed (%s)", path,
                WTERMSIG(status) == SIGKILL ? "killed, perhaps out of memory" : strsignal(WTERMSIG(status)));
  else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    int code = 0, skip = 0;
    if (got && sscanf(msg, "%d %n", &code, &skip) >= 1 && code > RR_OK && code <= RR_ERROR_UNSUPPORTED)
      e = rr_fail(dev, (rr_error)code, "%s", msg + skip);
    else
      e = rr_fail(dev, RR_ERROR_PARSE, "cannot read scene '%s': the import process failed (exit status %d)", path,
                  WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  }
  if (!e) {
    struct stat st;
    void *map = MAP_FAILED;
    if (fstat(memfd, &st) == 0 && st.st_size > 0)
      map = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, memfd, 0);
    if (map == MAP_FAILED)
      e = rr_fail(dev, RR_ERROR_MEMORY, "cannot read scene '%s': cannot map the imported scene: %s", path,
                  strerror(errno));
    else {
      e = read_scene(s, path, map, (size_t)st.st_size);
      munmap(map, (size_t)st.st_size);
    }
  }
  close(memfd);
  return e;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
/* The sanitizers' allocators (GCC 12's libasan; libtsan too, seen in test_threads)
 * are not safe across fork: a child forked while another thread allocates can block
 * forever on the lock that thread held. So sanitizer builds import in process while
 * other threads run; glibc's malloc, which other builds use, is safe across fork. */
static bool fork_unsafe(void) {
  FILE *f = fopen("/proc/self/status", "r");
  char line[128];
  int threads = 0;
  while (f && fgets(line, sizeof line, f))
    if (sscanf(line, "Threads: %d", &threads) == 1) break;
  if (f) fclose(f);
  return threads != 1;
}
#else
static bool fork_unsafe(void) { return false; }
#endif

rr_error rr_scene_import_guarded(rr_scene *s, const char *path) {
  rr_device *dev = s->dev;
  rr_import_limits lim;
  if (dev && dev->import_set) lim = dev->import;
  else rr_import_limits_init(&lim);
  char why[400];
  if ((!dev || dev->import_hook != IMPORT_HOOK_NO_CHECK) && !rr_import_check(path, why, sizeof why))
    return rr_fail(dev, RR_ERROR_PARSE, "cannot read scene '%s': %s", path, why);
  /* no device to carry the child's message: in process */
  if (lim.in_process || !dev || fork_unsafe()) return rr_scene_import_file(s, path);
  return import_guarded(s, path, &lim);
}
