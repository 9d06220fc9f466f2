/* scene_files.h — what the scene tests (tests/unit/test_scene_*.c) share:
 * small glTF and image files written into the group's temporary directory
 * (test_dir) and loaded from there, the standard one-triangle buffer, and
 * the warnings a load sends to the log. */
#ifndef AJAR_SCENE_FILES_H
#define AJAR_SCENE_FILES_H
#include "testutil.h"

#include "ajar.h"
#include "scene/scene.h"

#define EPS 1e-5f

/* a within EPS of (x, y, z), component by component. */
void assert_v3(V3 a, float x, float y, float z);

/* test_dir/name with the given bytes or text. */
void write_bytes(const char *name, const void *data, size_t n);
void write_text(const char *name, const char *text);
/* test_dir/name loaded; fails the test if it does not load. */
Scene *load_ok(const char *name);
/* The load fails with `status`, and the message names the file and holds
 * `needle` (the element and what is wrong with it). */
void load_fails(const char *name, ajar_status status, const char *needle);

/* ---- The standard one-triangle buffer ------------------------------------
 * (0,0,0) (1,0,0) (0,1,0), normals +Z, u16 indices 0 1 2: 78 bytes with
 * views at 0 (positions), 36 (normals), 72 (indices); `bad` replaces the
 * second vertex's x. Returns the size. */
size_t tri_bin(uint8_t *b, const uint16_t idx[3], float bad);
extern const uint16_t idx012[3];

#define TRI_BUFFERS(uri)                                                                                         \
	"\"buffers\":[{\"uri\":\"" uri "\",\"byteLength\":78}],"                                               \
	"\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"                                  \
	"{\"buffer\":0,\"byteOffset\":36,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":72,\"byteLength\":6}]," \
	"\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}]"

#define TRI_ACCESSORS(npos)                                                                                   \
	"\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" #npos ",\"type\":\"VEC3\"},"      \
	"{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                            \
	"{\"bufferView\":2,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]"

/* test_dir/tri.bin: the standard buffer. */
void write_tri_bin(void);
/* One triangle mesh in tri.bin, with the given scene nodes, nodes, and
 * `more` added to the scene object (its extras). */
void write_tri_gltf(const char *name, const char *scene_nodes, const char *nodes, const char *more);

/* Warnings sent to the log callback (count_warnings, set by the caller)
 * while a test loads something: how many, and the last one. */
extern int warnings;
extern char last_warning[2048];
void count_warnings(ajar_log_level level, const char *message, void *user);
#endif
