/* ajar.h — the public C API of Ajar, an unbiased OpenCL renderer for glTF
 * scenes lit through openings (portal-based bidirectional path tracing).
 *
 * Conventions: every fallible call returns an ajar_status; on failure the
 * message (naming the file and the place in it where there is one) is kept
 * per thread and returned by ajar_last_error(), and sent to the log callback
 * if one is set. The library never exits or aborts. Handles are opaque;
 * destroy functions take the handle's address and clear it. */
#ifndef AJAR_H
#define AJAR_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AJAR_VERSION_MAJOR 0
#define AJAR_VERSION_MINOR 1
#define AJAR_VERSION_PATCH 0
#define AJAR_VERSION_STRING "0.1.0"

typedef enum {
	AJAR_OK = 0,
	AJAR_ERROR_INVALID_ARGUMENT = 1, /* a caller's mistake */
	AJAR_ERROR_BAD_INPUT = 2,        /* a scene or image file is malformed */
	AJAR_ERROR_IO = 3,               /* cannot read or write a file */
	AJAR_ERROR_DEVICE = 4,           /* OpenCL: no device, build or run failure */
	AJAR_ERROR_OUT_OF_MEMORY = 5,
	AJAR_ERROR_CANCELLED = 6         /* stopped by the caller; the image is valid */
} ajar_status;

/* Message of the last failure on this thread ("" if none). */
const char *ajar_last_error(void);
const char *ajar_status_name(ajar_status status);
const char *ajar_version(void);

typedef enum { AJAR_LOG_ERROR, AJAR_LOG_WARNING, AJAR_LOG_INFO } ajar_log_level;
typedef void (*ajar_log_fn)(ajar_log_level level, const char *message, void *user);
/* Process-wide; NULL restores the default (silence). */
void ajar_set_log_callback(ajar_log_fn fn, void *user);

/* ---- Scenes ------------------------------------------------------------ */

typedef struct ajar_scene ajar_scene;

/* Loads .gltf (with .bin, images) or .glb. Portals are mesh nodes with
 * extras {"portal": true}; the environment comes from scene extras. */
ajar_status ajar_scene_load(const char *path, ajar_scene **out);
/* How ajar_scene_load_with reads a scene. By default every file the scene
 * names (buffer and image URIs, the environment image in its extras) must
 * resolve, after ".." and symbolic links, inside the scene file's folder;
 * anything else fails with AJAR_ERROR_BAD_INPUT naming the URI. A render
 * service that renders other people's files keeps this default. */
typedef struct {
	int allow_outside_files; /* 1: files anywhere may be read (trusted scenes) */
} ajar_load_options;
void ajar_load_options_default(ajar_load_options *o);
/* ajar_scene_load is ajar_scene_load_with(path, NULL, out): confined. */
ajar_status ajar_scene_load_with(const char *path, const ajar_load_options *o, ajar_scene **out);
/* An empty scene to be filled in code. */
ajar_status ajar_scene_create(ajar_scene **out);
void ajar_scene_destroy(ajar_scene **scene);

typedef struct {
	float base_color[3];     /* linear RGB */
	float metallic;          /* 0..1 */
	float roughness;         /* 0..1, perceptual (GGX alpha = roughness^2) */
	float specular;          /* KHR_materials_specular factor: 0 = pure Lambertian */
	float transmission;      /* 0..1, KHR_materials_transmission */
	float ior;               /* KHR_materials_ior */
	float emission[3];       /* emitted radiance, W sr^-1 m^-2 */
	int double_sided;
	/* KHR_materials_volume: thickness 0 (the default) makes transmission
	 * thin-walled (a pane: no refraction); above 0 the mesh is a closed
	 * solid that refracts and absorbs, attenuation_color remaining after
	 * attenuation_distance inside (0: no absorption). */
	float thickness;
	float attenuation_color[3];
	float attenuation_distance;
} ajar_material;
void ajar_material_default(ajar_material *m); /* white Lambertian */
ajar_status ajar_scene_add_material(ajar_scene *s, const ajar_material *m, uint32_t *id);

typedef struct {
	const float *positions;  /* 3 per vertex */
	const float *normals;    /* 3 per vertex, or NULL */
	const float *uvs;        /* 2 per vertex, or NULL */
	uint32_t vertex_count;
	const uint32_t *indices; /* 3 per triangle, or NULL: vertices taken in threes */
	uint32_t triangle_count;
	uint32_t material;       /* from ajar_scene_add_material */
	const float *transform;  /* column-major 4x4 (as glTF), or NULL for identity */
} ajar_mesh;
ajar_status ajar_scene_add_mesh(ajar_scene *s, const ajar_mesh *mesh);
/* A portal: triangles invisible to every ray, marking an opening. */
ajar_status ajar_scene_add_portal(ajar_scene *s, const ajar_mesh *mesh);

typedef struct {
	float position[3];
	float target[3];
	float up[3];
	float yfov;   /* vertical field of view, radians */
	float aspect; /* width / height; 0 = take it from the image size */
} ajar_camera;
ajar_status ajar_scene_set_camera(ajar_scene *s, const ajar_camera *c);
ajar_status ajar_scene_set_environment_color(ajar_scene *s, const float rgb[3]);
/* Equirectangular OpenEXR (any compression) or Radiance .hdr (told by its
 * header), +Y up, importance-sampled. Negative pixel values become 0 with
 * one warning; NaN or Inf is refused, naming the pixel. */
ajar_status ajar_scene_set_environment_image(ajar_scene *s, const char *exr_path, float strength);
/* Turns the environment by `degrees` about +Y, right-handed: positive is
 * counter-clockwise seen from above, so what the unturned image shows
 * toward +X moves toward -Z at 90. For either kind of environment, set
 * before or after; default 0. */
ajar_status ajar_scene_set_environment_rotation(ajar_scene *s, float degrees);

/* KHR_lights_punctual lights, in glTF's units: a directional light's
 * intensity is illuminance in lux, a point or spot light's luminous
 * intensity in candela; Ajar renders them as Blender's glTF importer does
 * by default ("Standard"): 683 lm/W, so radiance-like RGB = colour x
 * intensity / 683 (W/m^2 perpendicular to a directional light, W/sr from a
 * point or spot light). */
typedef enum { AJAR_LIGHT_DIRECTIONAL = 0, AJAR_LIGHT_POINT = 1, AJAR_LIGHT_SPOT = 2 } ajar_light_type;
typedef struct {
	ajar_light_type type;
	float position[3];  /* point, spot: world space */
	float direction[3]; /* directional, spot: the way the light travels (glTF: the node's -Z) */
	float color[3];     /* linear RGB multiplier, >= 0 */
	float intensity;    /* lux (directional) or candela (point, spot), >= 0 */
	float range;        /* point, spot: distance where the light ends; 0 = infinite */
	float inner_cone;   /* spot: radians, 0 <= inner < outer */
	float outer_cone;   /* spot: radians, outer <= pi/2 */
} ajar_light;
/* A white point light of 1 cd at the origin pointing down -Z, cones 0 and pi/4
 * (the glTF defaults). */
void ajar_light_default(ajar_light *l);
ajar_status ajar_scene_add_light(ajar_scene *s, const ajar_light *l);
/* Light `index` (0 .. ajar_scene_info.lights - 1) as added or loaded. */
ajar_status ajar_scene_light_get(const ajar_scene *s, uint32_t index, ajar_light *out);

typedef struct {
	uint64_t triangles;
	uint32_t materials;
	uint32_t emissive_triangles;
	uint32_t portal_triangles;
	uint32_t portals;
	uint32_t textures;
	int environment;         /* 0 none, 1 colour, 2 image */
	float bounds_min[3], bounds_max[3];
	ajar_camera camera;
	int has_camera;          /* 0: a default view framing the bounds is used */
	uint32_t width, height;  /* suggested resolution (glTF extras), or 0 */
	/* Images used as each kind of texture (an image used as two kinds
	 * counts in both). */
	uint32_t base_color_textures, metallic_roughness_textures, emissive_textures;
	uint64_t texture_bytes;  /* texel memory on a device */
	uint64_t alpha_triangles; /* triangles whose alpha (MASK, BLEND) rays test */
	uint32_t normal_textures; /* images used as normal maps */
	uint32_t lights;         /* KHR_lights_punctual lights (ajar_scene_light_get) */
} ajar_scene_info;
ajar_status ajar_scene_info_get(const ajar_scene *s, ajar_scene_info *info);

/* A portal found without markup: a rectangle over an opening (a window, a
 * door ajar, a roof opening) through which light from outside the camera's
 * space (a sky, a sun, emitters or lamps beyond it) reaches it. */
typedef struct {
	float center[3];
	float normal[3];            /* unit, facing into the camera's space */
	float half_u[3], half_v[3]; /* half sides: corners center +- half_u +- half_v */
	float width, height;        /* 2 |half_u|, 2 |half_v| */
	float share;                /* its share of the light-carrying rays the search found */
} ajar_portal;
/* Searches the scene's openings from its camera, as a render does where
 * the scene marks no portals (ajar_options.portals): the same scene gives
 * the same portals. Up to `capacity` of them, largest share first, go to
 * out; *count gets how many were found, *seconds (may be NULL) the
 * search's time. Marked portals are not listed. */
ajar_status ajar_scene_find_portals(const ajar_scene *s, ajar_portal *out, uint32_t capacity, uint32_t *count,
				    double *seconds);

/* ---- Render options ---------------------------------------------------- */

typedef enum { AJAR_INTEGRATOR_PT = 0, AJAR_INTEGRATOR_BDPT = 1, AJAR_INTEGRATOR_PORTAL = 2 } ajar_integrator;
/* The bidirectional integrators' MIS heuristic. AJAR_MIS_AUTO (the default):
 * the balance heuristic where a sky image's sun shining in through the
 * portals is the only light, the power heuristic elsewhere. */
typedef enum { AJAR_MIS_POWER = 0, AJAR_MIS_BALANCE = 1, AJAR_MIS_AUTO = 2 } ajar_mis;
/* Which portals a render samples through. A portal only steers samples:
 * every choice gives the same image on average, with more or less noise. */
typedef enum {
	AJAR_PORTALS_DEFAULT = 0, /* the scene's marked portals if it marks any, else found ones */
	AJAR_PORTALS_MARKED = 1,  /* the marked ones only (none where none is marked) */
	AJAR_PORTALS_FOUND = 2,   /* found ones (ajar_scene_find_portals); marked ones are ignored */
	AJAR_PORTALS_NONE = 3     /* none */
} ajar_portals;
/* Longest path (segments) the bidirectional integrators take. */
#define AJAR_BIDIR_MAX_DEPTH 32

/* ajar_options.aov bits. Each AOV is an unbiased pixel average (the same
 * jittered camera rays as the image), identical across devices, passes,
 * resumes and integrators. Albedo and normal are those of the first
 * non-specular hit, through mirrors and smooth glass (as Open Image Denoise
 * asks); an escaped ray adds zeros. */
#define AJAR_AOV_ALBEDO 1u   /* base colour (textured), linear RGB */
#define AJAR_AOV_NORMAL 2u   /* world-space shading normal, toward the viewer */
#define AJAR_AOV_DEPTH 4u    /* distance from the camera to the first hit */
#define AJAR_AOV_VARIANCE 8u /* variance of the pixel mean of the pixel's own samples */
#define AJAR_AOV_ALL 15u

typedef struct {
	uint32_t width, height;  /* 0: scene's suggestion, else 512 x 512/aspect */
	uint32_t spp;            /* samples per pixel; 0 = until time_limit or noise */
	double time_limit;       /* seconds; 0 = none */
	double noise;            /* stop once the image's estimated relative error (ajar_renderer_noise)
				  * is below this, e.g. 0.05 for 5%; spp and time_limit bound it; 0 = none */
	ajar_integrator integrator;
	uint32_t max_depth;      /* maximum path segments (camera segment included) */
	uint32_t min_depth;      /* paths of fewer segments are left out (0: none) */
	uint32_t seed;
	ajar_mis mis;            /* bidirectional integrators' MIS heuristic */
	ajar_portals portals;    /* which portals: marked, found or none (default: marked, else found) */
	uint32_t strategy_len;   /* bdpt, portal: keep one image per strategy for paths
				  * of up to this many segments (1..8), 0 = none */
	int strategy_unweighted; /* those images without MIS weights */
	const char *device;      /* selector ("0:0", "cpu", "gpu", name substring), a comma-
				  * separated list of them or "all" (render on several
				  * devices at once), or NULL for the first CPU device */
	uint32_t aov;            /* AJAR_AOV_* bits: first-hit outputs for denoisers */
} ajar_options;
void ajar_options_default(ajar_options *o);

/* ---- Renderer ---------------------------------------------------------- */

typedef struct {
	uint64_t samples_done;   /* samples per pixel done, summed over all pixels / pixels */
	uint32_t spp_done;
	uint32_t spp_target;     /* 0 if time-limited */
	double elapsed;          /* seconds */
	double samples_per_second; /* pixel samples per second */
	double eta;              /* seconds, < 0 if unknown */
	double fraction;         /* 0..1 */
	double noise;            /* with ajar_options.noise: the image's estimated relative
				  * error (ajar_renderer_noise), < 0 until known */
} ajar_progress;
/* Called after each pass; return non-zero to stop after that pass. */
typedef int (*ajar_progress_fn)(const ajar_progress *p, void *user);

typedef struct ajar_renderer ajar_renderer;

/* Builds the BVH and tables, compiles (or loads cached) kernels, uploads. */
ajar_status ajar_renderer_create(const ajar_scene *scene, const ajar_options *o, ajar_renderer **out);
void ajar_renderer_destroy(ajar_renderer **r);
/* Renders until spp or time_limit, or until cancelled (AJAR_ERROR_CANCELLED,
 * with a valid image of the samples done). With several devices, each takes
 * sample ranges in proportion to its speed; a device that fails is dropped
 * with a warning (log callback) and the others finish the image. If none is
 * left: AJAR_ERROR_DEVICE, and the image holds the samples rendered before. */
ajar_status ajar_renderer_render(ajar_renderer *r, ajar_progress_fn fn, void *user);
/* Safe from a signal handler or another thread. */
void ajar_renderer_cancel(ajar_renderer *r);
/* Clears the image and starts over with another seed, keeping the
 * prepared scene and compiled kernels: independent renders for variance
 * estimates cost no set-up. Not while a render runs. */
ajar_status ajar_renderer_restart(ajar_renderer *r, uint32_t seed);
uint32_t ajar_renderer_spp(const ajar_renderer *r);
/* With ajar_options.noise, the image's estimated relative error when it was
 * last estimated (< 0 before): sqrt of the mean over pixels and channels of
 * var(I) / (I^2 + (0.1 mean I)^2), var(I) from the difference of two
 * disjoint halves of the samples (src/render/README.md, "Stopping at a
 * noise level"); light-traced splats included, the same for every
 * integrator. */
double ajar_renderer_noise(const ajar_renderer *r);
/* The current estimate: width * height RGBA floats, row-major, top row first.
 * Not while ajar_renderer_render runs (call it before or after). */
ajar_status ajar_renderer_image(ajar_renderer *r, float *rgba, uint32_t *width, uint32_t *height);
ajar_status ajar_renderer_write_exr(ajar_renderer *r, const char *path);
ajar_status ajar_renderer_write_png(ajar_renderer *r, const char *path);
/* The AOV images: width * height * 10 floats, row-major, top row first:
 * albedo RGB, normal XYZ, depth, variance RGB (zeros for AOVs not asked
 * for). ajar_renderer_write_exr adds the asked ones to the EXR as
 * albedo.R/G/B, normal.X/Y/Z, depth.Z, variance.R/G/B. */
ajar_status ajar_renderer_aovs(ajar_renderer *r, float *px);
/* The image plus one RGB layer per strategy of paths up to
 * options.strategy_len segments (bdpt, portal): "len<n>.s<s>t<t>.R" etc. for
 * bdpt's (s, t), "len<n>.portal.s<s>t<t>.R" for the portal integrator's
 * intermediate strategies grouped by light and eye vertices. */
ajar_status ajar_renderer_write_strategies(ajar_renderer *r, const char *path);
/* The device(s) used, for reports. */
const char *ajar_renderer_device_name(const ajar_renderer *r);
/* The portals the renderer found over the scene's openings
 * (ajar_options.portals): up to `capacity` into out, *count how many (0
 * where it samples through marked portals or none), *seconds (may be
 * NULL) the search's time. */
ajar_status ajar_renderer_found_portals(const ajar_renderer *r, ajar_portal *out, uint32_t capacity, uint32_t *count,
					double *seconds);

/* Per-device figures of a renderer with several devices (ajar_options.device
 * "all" or a comma-separated list), for progress reports. Safe to call during
 * a render, from the progress callback too. */
typedef struct {
	char name[128];
	char selector[32];         /* as ajar_device_info.selector */
	uint64_t samples;          /* pixel samples of this device in the image */
	double samples_per_second; /* pixel samples per second while it rendered */
	double share;              /* samples / all devices' samples, 0..1 */
	int failed;                /* 1: dropped after an error, the others went on */
} ajar_device_stats;
/* Devices the renderer opened (including any dropped later). */
uint32_t ajar_renderer_device_count(const ajar_renderer *r);
ajar_status ajar_renderer_device_stats(const ajar_renderer *r, uint32_t index, ajar_device_stats *out);

/* ---- Checkpoints ------------------------------------------------------- */

/* A checkpoint holds a render's films (integer sums, splats, strategy
 * layers), the sample ranges done, the seed, the options and hashes of the
 * prepared scene and the render parameters. A render stopped and resumed
 * any number of times gives the same bits as an uninterrupted one on the
 * same kind of device. Files are written atomically (temporary name, fsync,
 * rename): a write that fails keeps the previous file. */

/* Writes r's state to `path`. Not while ajar_renderer_render runs (use
 * ajar_renderer_set_checkpoint for that); call it after a render returns,
 * whatever its status, to keep the samples done. */
ajar_status ajar_renderer_write_checkpoint(ajar_renderer *r, const char *path);
/* During ajar_renderer_render: write a checkpoint to `path` every
 * `every_seconds` (0: only when a device is dropped) and when a device is
 * dropped; the devices wait while it is written. A failed write is a
 * warning (log callback) and the render goes on. NULL path: none. */
ajar_status ajar_renderer_set_checkpoint(ajar_renderer *r, const char *path, double every_seconds);
/* The options a checkpoint was made with (device NULL, width and height
 * resolved) and, if spp_done is not NULL, the samples per pixel it holds
 * (then the whole file is checked, else only its header). */
ajar_status ajar_checkpoint_options(const char *path, ajar_options *o, uint32_t *spp_done);
/* A renderer that continues the checkpoint at `path`. o NULL: the
 * checkpoint's options; else o must equal them (ajar_checkpoint_options)
 * except spp, time_limit (total seconds, the checkpoint's time included)
 * and device. A checkpoint of another scene, version or parameter set, or
 * a truncated or corrupted one, is AJAR_ERROR_BAD_INPUT; the file is only
 * read. */
ajar_status ajar_renderer_resume(const ajar_scene *scene, const char *path, const ajar_options *o,
				 ajar_renderer **out);

/* ---- Images ------------------------------------------------------------ */

/* Writes float RGBA (width * height * 4, top row first) as an OpenEXR file;
 * `attrs` are extra string header attributes as name/value pairs. */
ajar_status ajar_write_exr(const char *path, const float *rgba, uint32_t width, uint32_t height,
			   const char *const *attrs, uint32_t nattrs);
/* Reads an OpenEXR's R, G, B (and A if present, else 1) into a new array
 * that the caller frees with free(). */
ajar_status ajar_read_exr(const char *path, float **rgba, uint32_t *width, uint32_t *height);
/* Tone-mapped (exposure, sRGB) 8-bit PNG of float RGBA. */
ajar_status ajar_write_png(const char *path, const float *rgba, uint32_t width, uint32_t height);

/* ---- Devices ----------------------------------------------------------- */

typedef struct {
	char selector[32];  /* what --device / ajar_options.device accepts, e.g. "0:1" */
	char platform[128];
	char name[128];
	char type[16];      /* "cpu", "gpu", "accelerator", "other" */
	uint32_t compute_units;
	uint64_t global_memory; /* bytes */
} ajar_device_info;

/* Lists every OpenCL device of every platform. *count may be 0. */
ajar_status ajar_devices(ajar_device_info *out, uint32_t capacity, uint32_t *count);

/* ---- Several machines (Open MPI) ---------------------------------------------
 * A program started by mpirun calls ajar_mpi_init first; every rank then
 * loads the same scene and makes the same calls with the same options:
 * ajar_renderer_create, ajar_renderer_resume and ajar_renderer_render are
 * collective (and ajar_renderer_restart is made on every rank). Each rank renders on its own devices (ajar_options.device
 * applies per rank); rank 0 deals the sample ranges to every device of
 * every rank by measured speed, decides when to stop (time limit, cancel)
 * and, once ajar_renderer_render returns, its renderer holds the whole
 * job's image, strategy layers, AOVs and statistics (the integer films of
 * every rank summed): the same bits as one process on the same kind of
 * device. Only rank 0 writes files; a resumed job reads the checkpoint on
 * rank 0 only. The other ranks' renderers hold nothing to write. */

/* 1 if the library was built with Open MPI. */
int ajar_mpi_available(void);
/* Initialises MPI when the process was started by mpirun (else, or
 * without MPI built in, does nothing: one rank). */
ajar_status ajar_mpi_init(int *argc, char ***argv);
/* This rank (0 alone) and the number of ranks (1 alone). */
int ajar_mpi_rank(void);
int ajar_mpi_size(void);
/* Collective: every rank passes its code (0: fine); returns the first
 * non-zero code in rank order, the same on every rank. */
int ajar_mpi_agree(int code);
/* Ends MPI if ajar_mpi_init started it. */
void ajar_mpi_finalize(void);

#ifdef __cplusplus
}
#endif
#endif
