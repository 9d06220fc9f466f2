/* types.h — every struct the host uploads and the kernels read.
 *
 * Compiled as OpenCL C and as C11. Only int, uint, float and V3 fields; sizes
 * are multiples of 16 with named padding. src/device/layout_check.c checks sizes and
 * offsets with static asserts on the host, and tests/test_layout.c compares
 * them with what a probe kernel reports on the device. */
#ifndef AJAR_TYPES_H
#define AJAR_TYPES_H
#include "base/vec.h"

/* Eight-wide BVH node (src/prepare/bvh_build.c collapses its binary SAH tree into these).
 * Slot i holds a child's box, one array per bound so the traversal tests
 * the eight boxes side by side, and child[i]: >= 0 an interior node; <= -1
 * a leaf, -1 - (4 first + count - 1), for triangles [first, first + count)
 * of the reordered triangle array, 1 <= count <= 4 (BVH_LEAF, kernels/geom/bvh.h);
 * BVH_EMPTY an unused slot, whose box is the point (+inf, +inf, +inf), which
 * no ray from a finite origin enters. Node 0 is the root. */
#define BVH_WIDTH 8
typedef struct {
	float lo_x[BVH_WIDTH], lo_y[BVH_WIDTH], lo_z[BVH_WIDTH];
	float hi_x[BVH_WIDTH], hi_y[BVH_WIDTH], hi_z[BVH_WIDTH];
	int child[BVH_WIDTH];
	int pad[BVH_WIDTH]; /* to four whole cache lines */
} BvhNode; /* 256 */

/* A copy of a mesh: its triangles in object space under their own BVH
 * (child BVH_INSTANCE(i) of a top-level slot, kernels/geom/bvh.h), placed
 * by an affine transform: p_world = xf p_obj, rows of 3x4, and inv its
 * inverse. Normals go by inv's transpose, tangents by xf; a mirroring
 * transform (negative determinant, INSTANCE_MIRROR) turns the bitangent
 * sign over. Its triangles never emit (emissive primitives are flattened,
 * src/scene/gltf.cpp), so the light tables see world-space triangles only. */
#define INSTANCE_MIRROR 1
typedef struct {
	float xf[12];  /* object to world, row-major 3x4 */
	float inv[12]; /* world to object */
	int root;      /* its mesh's BVH root node */
	int flags;     /* INSTANCE_* */
	int mesh;
	int pad0;
} Instance; /* 112 */

/* Triangle as traversal sees it. `emitter` indexes Emitter (or -1). */
#define TRI_EXTRA 1 /* has TriExtra data (TEXCOORD_1, COLOR_0) */
#define TRI_ALPHA 2 /* its material may be transparent here: rays test its alpha (bvh.h) */
#define TRI_TANGENT 4 /* normal-mapped: TriExtra holds its tangents */
#define TRI_PANE 8    /* thin-walled transmissive material that may be smooth here: a pane that shadow
		       * rays and connections pass through by its transmittance (geom/visibility.h) */
typedef struct {
	V3 p0, p1, p2;
	int material;
	int emitter;
	int flags;  /* TRI_* */
} Tri; /* 48 */

/* Shading attributes of the triangle with the same index. */
typedef struct {
	V3 n0, n1, n2;   /* vertex normals, world space, unit */
	float u0, v0, u1, v1, u2, v2;
	int has_normals; /* 0: use the geometric normal */
} TriShade; /* 64 */

/* The attributes few meshes have, for triangles with TRI_EXTRA: the
 * array has one entry per triangle where any has them, else one. */
typedef struct {
	float u0, v0, u1, v1, u2, v2; /* TEXCOORD_1 */
	float c0[4], c1[4], c2[4];    /* COLOR_0, linear RGBA */
	float t0[4], t1[4], t2[4];    /* TRI_TANGENT: world-space tangent, w the bitangent's sign */
	int pad0, pad1;
} TriExtra; /* 128 */

#define MATERIAL_DOUBLE_SIDED 1
#define MATERIAL_ALPHA_MASK 2   /* alpha below alpha_cutoff is a hole */
#define MATERIAL_ALPHA_BLEND 4  /* stochastic transparency: rays meet the surface with probability alpha */
#define MATERIAL_VOLUME 8       /* KHR_materials_volume with a thickness: transmission refracts into a solid
				 * (absorbing by `sigma` inside); without it glTF's transmission is thin-walled */
#define MATERIAL_TINTED 16      /* specular_color (or its texture) tints the dielectric F0; else it is unread */

/* glTF metallic-roughness, with KHR_materials_specular/transmission/ior/volume
 * and the layers and anisotropy Blender writes: KHR_materials_sheen,
 * _clearcoat, _anisotropy (material/bsdf.h). Texture fields hold a Texture
 * index + 1 (0: none). */
typedef struct {
	V3 base_color;      /* linear RGB factor */
	int base_tex;       /* Texture index or -1; multiplies base_color */
	V3 emission;        /* radiance, W sr^-1 m^-2 (factor x strength) */
	float metallic;
	float roughness;    /* perceptual; GGX alpha = roughness^2 */
	float transmission;
	float ior;
	float specular;     /* KHR_materials_specular factor; 0 = pure diffuse */
	int flags;          /* MATERIAL_* */
	float alpha_cutoff;
	int mr_tex;         /* Texture index + 1 (0: none): B metallic, G roughness, times the factors */
	int emissive_tex;   /* Texture index + 1 (0: none): multiplies emission */
	float base_alpha;   /* baseColorFactor's alpha (MASK, BLEND) */
	int normal_tex;     /* Texture index + 1 (0: none): tangent-space normal map */
	float normal_scale; /* its x and y scale */
	int transmission_tex; /* Texture index + 1 (0: none): R multiplies transmission */
	V3 sigma;           /* MATERIAL_VOLUME: absorption per unit length inside (Beer-Lambert), 0 = clear */
	int specular_tex;   /* A multiplies specular */
	V3 specular_color;  /* KHR_materials_specular colour factor: tints the dielectric F0 (white: none) */
	int specular_color_tex; /* RGB (sRGB) multiplies specular_color */
	V3 sheen_color;     /* KHR_materials_sheen colour factor; black: no sheen */
	float sheen_roughness;
	int sheen_color_tex;  /* RGB (sRGB) multiplies sheen_color */
	int sheen_rough_tex;  /* A multiplies sheen_roughness */
	float clearcoat;      /* KHR_materials_clearcoat factor; 0: no clear coat */
	float clearcoat_roughness;
	int clearcoat_tex;    /* R multiplies clearcoat */
	int clearcoat_rough_tex; /* G multiplies clearcoat_roughness */
	int clearcoat_normal_tex; /* the clear coat's own normal map (else the unmapped normal) */
	float clearcoat_normal_scale;
	float anisotropy;     /* KHR_materials_anisotropy strength; 0: isotropic */
	float anisotropy_rotation; /* radians in [-pi, pi], counter-clockwise from the tangent */
	int anisotropy_tex;   /* RG: direction in tangent space (2c - 1), B multiplies the strength */
	int pad0;
} Material; /* 176 */

/* A texture as a material uses it: an RGBA8 image in the shared texel
 * array (decoded from sRGB only where it holds colour, surface.h), the
 * glTF sampler's wrap modes and filter, the texture coordinate set and
 * KHR_texture_transform as an affine map of (u, v). */
#define TEX_WRAP_REPEAT 0
#define TEX_WRAP_CLAMP 1
#define TEX_WRAP_MIRROR 2
#define TEX_WRAP_S(flags) ((flags) & 3)
#define TEX_WRAP_T(flags) (((flags) >> 2) & 3)
#define TEX_NEAREST 16 /* else bilinear */
#define TEX_UV1 32     /* reads TEXCOORD_1 (TriExtra) instead of TEXCOORD_0 */
typedef struct {
	int offset; /* first texel in `texels` */
	int width;
	int height;
	int flags;  /* TEX_* */
	float xf[6]; /* u' = xf[0] u + xf[1] v + xf[2], v' = xf[3] u + xf[4] v + xf[5] */
	int pad0, pad1;
} Texture; /* 48 */

/* Emissive triangle, or one cell of a triangle with an emissive texture;
 * chosen with probability proportional to its (textured) power. The cells
 * of one triangle are consecutive, Tri.emitter the first. */
typedef struct {
	int tri;
	float area;
	float pdf_select; /* probability of choosing this emitter */
	int cell;         /* EMITTER_LEVEL(cell): the triangle is split into 4^level cells,
			   * this entry is cell EMITTER_INDEX(cell) of them (lights.h) */
} Emitter; /* 16 */

#define EMITTER_CELL(level, index) ((level) << 24 | (index))
#define EMITTER_LEVEL(cell) ((cell) >> 24)
#define EMITTER_INDEX(cell) ((cell) & 0xffffff)

/* Portal triangle: invisible to every ray. The host measures the direct
 * light arriving through it from each side (src/prepare/portal_flux.c): that picks
 * the triangle for intermediate subpaths, the side their <- half leaves
 * toward, and the side the environment is seen through. */
typedef struct {
	V3 p0, p1, p2;
	V3 n;             /* unit, along (p1 - p0) x (p2 - p0) */
	float area;
	float pdf_select; /* choice for intermediate subpaths: by flux, area as defence */
	float side_plus;  /* probability that the <- half leaves toward +n */
	int env_side;     /* +1 / -1: the side of n the environment lies behind; 0 none */
} PortalTri; /* 64 */

/* Planar portal: coplanar, connected portal triangles with the sky behind
 * them, for next-event estimation of an environment image through them
 * (kernels/light/portal_sky.h, src/prepare/sky_tables.c). Frame (t, b, n): n unit toward
 * the sky, t along the longest edge; the triangles lie within the rectangle
 * [a0, a1] x [b0, b1] of (t, b) coordinates about o. `table` is the first
 * float of its summed-area table in portal_sky. */
typedef struct {
	V3 o;
	float a0;
	V3 t;
	float a1;
	V3 b;
	float b0;
	V3 n;
	float b1;
	int table;
	int pad0, pad1, pad2;
} PortalPlane; /* 80 */

/* KHR_lights_punctual light (src/prepare/light_tables.c converts glTF's photometric
 * units at 683 lm/W). A delta light: no ray hits it, next-event estimation
 * and light subpaths reach it deterministically. Chosen by power in the
 * same CDF as the emitters, after them (emitter_cdf[num_emitters + i]). */
#define LIGHT_DIRECTIONAL 0
#define LIGHT_POINT 1
#define LIGHT_SPOT 2
typedef struct {
	V3 pos;           /* point, spot */
	int type;         /* LIGHT_* */
	V3 dir;           /* unit, the way the light travels */
	float pdf_select; /* probability of choosing it in emitter_cdf */
	V3 intensity;     /* W/sr (point, spot), W/m^2 perpendicular (directional) */
	float range;      /* 0 = infinite */
	float cos_outer;  /* spot: cosine of the outer cone angle (point: -1) */
	float cone_scale; /* spot: 1 / max(0.001, cos inner - cos outer) */
	float disk_radius;/* directional: radius of the disk light subpaths start on */
	float pad0;
} PunctualLight; /* 64 */

#define ENV_NONE 0
#define ENV_COLOR 1
#define ENV_IMAGE 2

/* Pinhole camera. Raster (px, py) in [0,W)x[0,H), y down. */
typedef struct {
	V3 pos;
	float tan_half_fov_y; /* tan(yfov / 2) */
	V3 right;             /* unit */
	float aspect;         /* width / height of the image plane */
	V3 up;                /* unit */
	int width;
	V3 forward;           /* unit, view direction */
	int height;
} Camera; /* 64 */

#define INTEGRATOR_PT 0
#define INTEGRATOR_BDPT 1
#define INTEGRATOR_PORTAL 2

/* Params.mis: the MIS heuristic (mis.h), ajar_mis's values. */
#define MIS_POWER 0
#define MIS_BALANCE 1

/* The integrator a program runs. The host builds one program per integrator
 * (-DAJAR_INTEGRATOR=n), so a device compiles only the code it runs: GPU
 * compilers take minutes over all three inlined into one kernel. Without the
 * define (host tests, tools) it is read from Params. */
#ifdef AJAR_INTEGRATOR
#define PARAMS_INTEGRATOR(p) AJAR_INTEGRATOR
#else
#define PARAMS_INTEGRATOR(p) ((p)->integrator)
#endif

/* At most this many planes of panes mirror the sky for next-event
 * estimation (integrator/pane_mirror.h): windows in a wall share one, a
 * room has a few walls; a vertex pays only a side test for each plane. */
#define PANE_PLANES_MAX 8
/* A pane lies in such a plane where their normals' cosine exceeds
 * PANE_PLANE_COS and its points lie within PANE_PLANE_TOL of the scene's
 * radius of it. */
#define PANE_PLANE_COS 0.9999f
#define PANE_PLANE_TOL 1e-4f

/* Everything about a render that is not an array. One per upload. */
typedef struct {
	Camera camera;          /* 0 */
	int num_tris;           /* 64 */
	int num_emitters;
	int num_portals;
	int num_textures;
	int env_type;           /* 80, ENV_* */
	int env_width;          /* equirectangular, +Y up */
	int env_height;
	float env_strength;
	V3 env_color;           /* 96, ENV_COLOR radiance */
	float env_pdf_select;   /* probability NEE picks the environment */
	V3 scene_center;        /* 112, bounding sphere, for light subpaths */
	float scene_radius;
	int max_depth;          /* 128, maximum number of path segments */
	int rr_depth;           /* Russian roulette from this vertex on (1: first hit) */
	int integrator;         /* INTEGRATOR_* */
	uint seed;
	float emitter_power;    /* 144, total power of emissive triangles */
	float env_power;        /* power estimate of the environment */
	int mis;                /* MIS_POWER or MIS_BALANCE */
	int min_depth;          /* only paths of at least this many segments */
	int strategy_len;       /* 160, bdpt: per-strategy layers up to this path length, 0 = none */
	int strategy_unweighted;/* layers without MIS weights */
	int cross_filter;       /* pt, for tests: weight each path by its portal crossings on */
	int cross_lo;           /* eye-side edges cross_lo..(segments - 1 - cross_hi) (edge 0 */
	int cross_hi;           /* 176: leaves the camera); 0 = no filter */
	int portal_s_max;       /* intermediate strategies use at most this many light vertices, */
	int portal_sp_max;      /* <- vertices and */
	int portal_tp_max;      /* -> vertices (portal.h) */
	int light_paths;        /* 192, portal: 0 = no light subpaths (bdpt's s >= 2 and t = 1 left out) */
	int portal_t_max;       /* intermediate strategies use at most this many eye vertices */
	float portal_rate;      /* 200, probability that a pixel sample traces an intermediate subpath */
	float env_rotation;     /* radians about +Y, right-handed (env.h) */
	int num_lights;         /* 208, PunctualLight */
	float light_power;      /* their total power estimate (src/prepare/light_tables.c) */
	int num_portal_planes;  /* 216, planar portals with sky tables (env_portal.h), 0 = none */
	float env_rot_cos;      /* cos and sin of env_rotation, from the host in double */
	float env_rot_sin;      /* 224 (env.h, env_turn) */
	int bdpt_conn;          /* bdpt strategies other than light tracing use at most this many
	                         * non-delta light vertices (1 or 2; 0 = any; mis.h, mis_conn_limit) */
	int env_lines;          /* 232, a sky image's light subpaths start on lines through the
	                         * portals, their directions from the ENV_LINE_* tables (env.h) */
	int num_panes;          /* TRI_PANE triangles (geom/visibility.h) */
	int num_pane_planes;    /* 240, planes of panes whose mirror image of the sky next-event
	                         * estimation samples (integrator/pane_mirror.h), 0 = none */
	V3 pane_n[PANE_PLANES_MAX]; /* unit normals, toward each plane's sky side */
	float pane_d[PANE_PLANES_MAX]; /* the plane: dot(pane_n, x) = pane_d */
	int pad_pane[3];
} Params; /* 384 */

/* Layout of the float array `env`: for an ENV_IMAGE of W x H,
 *   [0, 3WH)                    linear RGB radiance, row-major, row 0 = top
 *   [3WH, 3WH + H + 1)          marginal CDF over rows
 *   [3WH + H + 1, .. + H(W+1))  conditional CDF of each row
 * The CDFs are of luminance x sin(theta), so sampling is in solid angle. */
#define ENV_PIXELS(w, h) 0
#define ENV_MARGINAL(w, h) (3 * (w) * (h))
#define ENV_CONDITIONAL(w, h) (3 * (w) * (h) + (h) + 1)
#define ENV_FLOATS(w, h) (3 * (w) * (h) + (h) + 1 + (h) * ((w) + 1))
/* With Params.env_lines, the same two CDFs again for the directions of
 * light subpaths that start on lines through the portals (env.h,
 * env_line_sample; src/prepare/portal_flux.c, portal_sky_lines_build). */
#define ENV_LINE_MARGINAL(w, h) ENV_FLOATS(w, h)
#define ENV_LINE_CONDITIONAL(w, h) (ENV_FLOATS(w, h) + (h) + 1)
#define ENV_LINE_FLOATS(w, h) (ENV_FLOATS(w, h) + (h) + 1 + (h) * ((w) + 1))

/* The device arrays, listed once: kernel arguments, the SceneView below and
 * the host upload are all generated from this list so they cannot drift. */
#define AJAR_SCENE_BUFFERS(X) \
	X(BvhNode, nodes)         \
	X(Tri, tris)              \
	X(TriShade, shade)        \
	X(Material, materials)    \
	X(Texture, textures)      \
	X(uint, texels)           \
	X(Emitter, emitters)      \
	X(float, emitter_cdf)     \
	X(float, env)             \
	X(PortalTri, portals)     \
	X(float, portal_cdf)      \
	X(TriExtra, extra)        \
	X(PunctualLight, punctual) \
	X(PortalPlane, portal_planes) \
	X(float, portal_sky)      \
	X(Instance, instances)    \
	X(Params, params)

/* What device code sees of the scene: one pointer per array. */
typedef struct {
#define AJAR_VIEW_FIELD(type, name) GLOBAL const type *name;
	AJAR_SCENE_BUFFERS(AJAR_VIEW_FIELD)
#undef AJAR_VIEW_FIELD
} SceneView;

#endif
