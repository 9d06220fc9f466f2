/* scene.h — the host's scene as loaded or built in code, before any
 * acceleration structure: growable arrays of the shared device types.
 *
 * The glTF loader and the public builder API both fill a Scene through the
 * functions below, which validate what they receive (finite positions,
 * indices in range, materials that exist) so nothing later has to. */
#ifndef AJAR_SCENE_H
#define AJAR_SCENE_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "base/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The largest environment image: 2^27 pixels (a 16384 x 8192 sky, 2 GiB
 * of float RGBA as it is read), from the header before the pixels are
 * allocated; image/hdr.c holds .hdr files to the same. */
#define SCENE_SKY_MAX_PIXELS ((uint64_t)1 << 27)
/* The arrays a scene shares with its renderers (scene_share.h). */
typedef struct SceneShare SceneShare;

/* A mesh kept once, in object space, for its instances: triangles
 * [first, first + count) of the scene's arrays. Meshes are in order of
 * `first` and do not overlap; every triangle outside them is a
 * world-space ("flat") one. */
typedef struct {
	uint32_t first, count;
} SceneMesh;

/* A copy of mesh `mesh` placed by m: object to world, rows of 3x4, its
 * determinant non-zero. */
typedef struct {
	uint32_t mesh;
	double m[12];
} SceneInstance;

/* The public ajar_scene handle is this struct. */
typedef struct ajar_scene {
	char *source;            /* file name for messages, or "<api>" */

	/* tris, shade, extra and texels are big arrays (core/big_array.h),
	 * held with the renderers through `share` once one was prepared:
	 * written only after scene_private(). */
	Tri *tris;               /* world space, insertion order until a renderer puts them in its BVH's */
	TriShade *shade;
	uint32_t ntris, cap_tris;

	Material *materials;
	uint32_t nmaterials, cap_materials;

	Texture *textures;
	uint32_t ntextures, cap_textures;
	uint32_t *texels;        /* RGBA8, R in the low byte */
	size_t ntexels, cap_texels;

	PortalTri *portals;      /* pdf_select is filled by the portal table */
	uint32_t nportal_tris, cap_portals;
	uint32_t nportals;       /* portal objects (nodes / API calls) */

	int has_camera;
	V3 cam_pos, cam_forward, cam_up;
	float cam_yfov, cam_aspect; /* aspect 0: from the image */

	uint32_t width, height;  /* suggested by the file, or 0 */

	int env_type;            /* ENV_* */
	V3 env_color;
	float env_strength;
	uint32_t env_width, env_height;
	float *env_rgb;          /* env_width * env_height * 3, row 0 = top (+Y) */
	float env_rotation;      /* radians about +Y, right-handed (kernels/light/env.h) */

	uint32_t nimages;        /* textures made by scene_add_texture (the others are uses of them) */
	TriExtra *extra;         /* NULL, or one per triangle once any has TEXCOORD_1 or COLOR_0 */
	size_t cap_extra;
	ajar_light *lights;      /* punctual lights, glTF units, direction unit */
	uint32_t nlights, cap_lights;
	SceneShare *share;       /* NULL until a renderer shares the arrays */
	double load_seconds;     /* ajar_scene_load's */
	SceneMesh *meshes;       /* instanced meshes (a renderer moves them after the flat triangles) */
	uint32_t nmeshes, cap_meshes;
	SceneInstance *instances;
	uint32_t ninstances, cap_instances;
} Scene;

ajar_status scene_new(const char *source, Scene **out);
void scene_free(Scene *s);
/* Makes tris, shade, extra and texels the scene's alone, to be written
 * (scene_share.c): copied if a renderer shares them. */
ajar_status scene_private(Scene *s);

/* Returns the new material's index in *id. */
ajar_status scene_add_material(Scene *s, const Material *m, uint32_t *id);
/* RGBA8 texels, row 0 first as stored in the image file. */
ajar_status scene_add_texture(Scene *s, uint32_t width, uint32_t height, const uint8_t *rgba,
			      uint32_t *id);
/* Another use of texture `image`'s texels with its own sampler and
 * coordinates: flags TEX_*, xf the affine map of (u, v) (kernels/base/types.h). */
ajar_status scene_add_texture_use(Scene *s, uint32_t image, int flags, const float xf[6], uint32_t *id);
/* Adds triangles already in world space. `normals` and `uvs` may be NULL.
 * `what` names the origin for messages (e.g. "meshes[2].primitives[0]"). */
ajar_status scene_add_triangles(Scene *s, const char *what, const float *pos, const float *normals,
				const float *uvs, uint32_t nverts, const uint32_t *idx, uint32_t ntris,
				uint32_t material);
/* scene_add_triangles with a second texture coordinate set (2 floats a
 * vertex), vertex colours (linear RGBA, 4 floats a vertex) and tangents
 * (world space xyz and the bitangent's sign w, 4 floats a vertex; used
 * where the material has a normal map), each may be NULL. */
ajar_status scene_add_triangles_ex(Scene *s, const char *what, const float *pos, const float *normals,
				   const float *uvs, const float *uvs1, const float *colors, const float *tangents,
				   uint32_t nverts,
				   const uint32_t *idx, uint32_t ntris, uint32_t material);
/* Makes triangles [first, s->ntris), added last, mesh *id: object space,
 * drawn only through instances. first must not lie before the last
 * mesh's end. */
ajar_status scene_add_mesh_range(Scene *s, const char *what, uint32_t first, uint32_t *id);
/* An instance of mesh `mesh` under the column-major 4x4 matrix m (glTF's;
 * its last row 0 0 0 1); refused if not finite or singular. */
ajar_status scene_add_instance(Scene *s, const char *what, uint32_t mesh, const double m[16]);
/* Triangles as rendered: the flat ones and every instance's. */
uint64_t scene_rendered_triangles(const Scene *s);
/* Triangles outside every mesh. */
uint32_t scene_flat_triangles(const Scene *s);
ajar_status scene_add_portal(Scene *s, const char *what, const float *pos, uint32_t nverts,
			     const uint32_t *idx, uint32_t ntris);
ajar_status scene_set_camera(Scene *s, V3 pos, V3 forward, V3 up, float yfov, float aspect);
void scene_set_env_color(Scene *s, V3 rgb);
/* Takes ownership of rgb (malloc'ed, w * h * 3 floats). */
ajar_status scene_set_env_image(Scene *s, uint32_t w, uint32_t h, float *rgb, float strength);
/* Reads the equirectangular image at `path` (OpenEXR, or Radiance .hdr
 * told by its header) and sets it; errors
 * name the file. Negative pixels become 0 with one warning; NaN or Inf is
 * refused, naming the pixel. */
ajar_status scene_load_env_image(Scene *s, const char *path, float strength);
/* Turns the sky by `degrees` about +Y, right-handed (counter-clockwise seen
 * from above); must be finite. Applies to any environment set before or
 * after. */
ajar_status scene_set_env_rotation(Scene *s, double degrees);

/* Validates and appends a punctual light (`what` names it for messages);
 * the direction is normalised. */
ajar_status scene_add_light(Scene *s, const char *what, const ajar_light *l);

/* Bounds of all renderable triangles (instances and portals included). */
void scene_bounds(const Scene *s, V3 *bmin, V3 *bmax);
/* Mesh k's bounds in object space, and an instance's world-space bounds
 * (the mesh's corners transformed in double, rounded outward). */
void scene_mesh_bounds(const Scene *s, uint32_t k, V3 *lo, V3 *hi);
void scene_instance_bounds(const SceneInstance *in, V3 mlo, V3 mhi, V3 *lo, V3 *hi);
/* The host scene's surfaces (triangles, shading, materials, textures) as
 * the kernels' surface code reads them; the other arrays are NULL. */
SceneView scene_surface_view(const Scene *s);
uint32_t scene_count_emissive(const Scene *s);
/* The camera to render with: the scene's, or, if it has none, a view along
 * -Z framing the bounding sphere (yfov 45 degrees). */
void scene_camera(const Scene *s, V3 *pos, V3 *forward, V3 *up, float *yfov);

#ifdef __cplusplus
}
#endif
#endif
