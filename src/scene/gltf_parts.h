/* gltf_parts.h — the parts of the glTF loader that need neither tinygltf
 * nor the document, shared by gltf.cpp and the C readers (gltf_loader.h):
 * node matrices and vertex transforms (gltf_transform.c), accessor data
 * and texels decoded (gltf_decode.c), the rule that keeps a mesh as
 * instances (gltf_instancing.c), the scene-folder check (gltf_confine.c),
 * reading a file the scene names (gltf_files.c), the extensions the loader
 * reads (gltf_extensions.c). */
#ifndef AJAR_GLTF_PARTS_H
#define AJAR_GLTF_PARTS_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Matrices are column-major 4x4, element (r, c) at [4c + r]. */
void gltf_mat_identity(double m[16]);
/* r = a b. */
void gltf_mat_mul(const double a[16], const double b[16], double r[16]);
/* T * R * S (translation, rotation quaternion x y z w, scale) into m; 0
 * (m untouched) where the quaternion is zero or not finite. */
int gltf_trs_matrix(const double t[3], const double q[4], const double s[3], double m[16]);
/* Inverse transpose of the upper 3x3 (cofactors over the determinant),
 * row-major nm[r][c]; returns the determinant. */
double gltf_normal_matrix(const double m[16], double nm[3][3]);
/* nv positions (3 floats each) by `world`, in double, in place. */
void gltf_transform_points(const double world[16], float *pos, size_t nv);
/* nv normals by the normal matrix nm, in place (not normalised). */
void gltf_transform_normals(const double nm[3][3], float *nrm, size_t nv);
/* nv tangents (4 floats each): xyz by world's 3x3, w negated if flip. */
void gltf_transform_tangents(const double world[16], float *tan, size_t nv, int flip);

/* glTF's componentType codes (those of OpenGL). */
enum {
	GLTF_BYTE = 5120,
	GLTF_UNSIGNED_BYTE = 5121,
	GLTF_SHORT = 5122,
	GLTF_UNSIGNED_SHORT = 5123,
	GLTF_UNSIGNED_INT = 5125,
	GLTF_FLOAT = 5126,
};
/* Primitive modes that make triangles. */
enum { GLTF_MODE_TRIANGLES = 4, GLTF_MODE_TRIANGLE_STRIP = 5, GLTF_MODE_TRIANGLE_FAN = 6 };
/* Samplers' filter and wrap codes. */
enum {
	GLTF_FILTER_NEAREST = 9728,
	GLTF_WRAP_CLAMP_TO_EDGE = 33071,
	GLTF_WRAP_MIRRORED_REPEAT = 33648,
};
/* Accessor types that are vectors (the matrices' codes add 32). */
enum { GLTF_VEC2 = 2, GLTF_VEC3 = 3, GLTF_VEC4 = 4, GLTF_SCALAR = 65 };
/* Bytes of one component; 0 for an unknown type. */
int gltf_component_size(int ctype);
/* Components of an accessor type: 1 to 4 for SCALAR to VEC4, 0 else. */
int gltf_type_components(int type);
/* n components of type ctype, tightly packed, as floats; normalized
 * integers map to [0, 1] or [-1, 1] as glTF specifies. */
void gltf_to_floats(const uint8_t *bytes, size_t n, int ctype, int normalized, float *out);
/* n unsigned indices of cs bytes each (1, 2 or 4) as uint32_t. */
void gltf_to_indices(const uint8_t *bytes, size_t n, int cs, uint32_t *out);
/* A triangle strip (strip != 0) or fan of n indices as a triangle list,
 * the degenerate stitching triangles dropped; out holds 3 (n - 2) at
 * most. Returns the number of indices written. */
size_t gltf_unroll(int strip, const uint32_t *in, size_t n, uint32_t *out);
/* n texels of comp (1-4) channels of `bytes` (1, or 2: the high byte is
 * kept) each as RGBA8: grey copied to RGB, alpha 255 where there is none. */
void gltf_rgba8(const unsigned char *img, size_t n, size_t comp, int bytes, uint8_t *rgba);

/* Whether a mesh of `triangles` drawn `uses` times is kept once, as
 * instances (GLTF_INSTANCING_AUTO's rule). */
int gltf_mesh_instanced(uint64_t triangles, uint64_t uses);
/* Triangles `count` vertices make in primitive mode `mode` (strips and
 * fans counted as drawn; points and lines none). */
uint64_t gltf_mode_triangles(int mode, uint64_t count);

/* Whether existing `path` resolves inside the folder `root` (symbolic
 * links resolved): 1 inside, 0 outside, -1 if it cannot be resolved.
 * `real` (PATH_MAX bytes) gets the resolved path. */
int gltf_path_inside(const char *root, const char *path, char *real);
/* Whether existing `path`, which the scene names `uri`, may be read: it
 * resolves inside `root`, or allow_outside. Where it resolves outside,
 * `why` (size bytes) gets the refusal naming the URI; else it is "". */
int gltf_confined(const char *root, int allow_outside, const char *path, const char *uri, char *why, size_t size);
/* Bytes for gltf_confined's `why`: more than a load's message holds. */
#define GLTF_WHY_SIZE 2048

/* Opens a file the scene names (a regular file of at most 4 GiB) into *fd
 * and gives its size; messages name `path`. */
ajar_status gltf_file_open(const char *path, int *fd, size_t *size);
/* Reads size bytes of fd (gltf_file_open's) into data and closes fd. */
ajar_status gltf_file_read(const char *path, int fd, unsigned char *data, size_t size);

/* Whether the loader implements extension `name` (len bytes): one a file
 * may require. */
int gltf_extension_supported(const char *name, size_t len);
/* Whether load_material reads material extension `name` (len bytes);
 * any other on a material is named in a warning. */
int gltf_material_extension_read(const char *name, size_t len);

#ifdef __cplusplus
}
#endif
#endif
