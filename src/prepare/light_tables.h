/* light_tables.h — the host tables that light sampling reads on the device
 * (kernels/light/lights.h): emissive triangles with a power CDF, the environment
 * image with its 2-D CDF (layout in kernels/base/types.h), and the portal area
 * CDF.
 *
 * All CDFs have n + 1 entries, cdf[0] = 0 and cdf[n] = 1 exactly, as
 * sample_cdf (kernels/sample/sampling.h) expects; every stored selection
 * probability is the width cdf[i + 1] - cdf[i] itself, so a sample's
 * probability and the pdf evaluated later agree to the bit. */
#ifndef AJAR_LIGHTS_H
#define AJAR_LIGHTS_H
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"
#include "scene/scene.h"

typedef struct {
	Emitter *emitters;
	float *emitter_cdf;    /* nemitters + 1 (one float if none) */
	uint32_t nemitters;
	float emitter_power;   /* W: sum of area x pi x luminance(emission) */
	/* ENV_IMAGE: ENV_FLOATS(w, h) floats, pixels already multiplied by the
	 * strength (the kernels do not apply Params.env_strength again).
	 * nenv = 0 for ENV_NONE / ENV_COLOR, with one float allocated so a
	 * device buffer can exist. */
	float *env;
	size_t nenv;
	float env_power;       /* W: pi R^2 x pi x average radiance luminance */
	float *portal_cdf;     /* nportals + 1 (one float if none) */
	uint32_t nportals;
	float env_pdf_select;  /* probability that light sampling picks the environment */
	/* Punctual lights, chosen in emitter_cdf after the emitters (which then
	 * has nemitters + nlights + 1 entries). */
	PunctualLight *lights; /* nlights (one if none) */
	uint32_t nlights;
	float light_power;     /* W: their power estimates, summed (src/prepare/light_tables.c) */
} LightTables;

/* `tris` is the array as uploaded (BVH order): each triangle's `emitter`
 * is set to its (first) Emitter index or -1, and Emitter.tri indexes this
 * array; `shade` and `extra` are in the same order (emissive textures
 * read their UVs).
 * `mats` has the scene's materials; `portals` (nportal_tris) get their
 * area and pdf_select written. The environment comes from `s`. On failure
 * *out is left empty (safe to lights_free). */
ajar_status lights_build(const Scene *s, Tri *tris, const TriShade *shade, const TriExtra *extra, uint32_t ntris, const Material *mats,
			 PortalTri *portals, uint32_t nportal_tris, V3 scene_center, float scene_radius,
			 LightTables *out);
void lights_free(LightTables *t);

/* The share of an equirect sky's power (w x h RGB pixels) in its brightest
 * 0.1% of solid angle, each texel's power times weight(x, y, ctx) when
 * weight is not NULL (src/prepare/light_tables.c). */
typedef double (*EnvTexelWeight)(uint32_t x, uint32_t y, void *ctx);
float env_sun_share_weighted(const float *pix, uint32_t w, uint32_t h, EnvTexelWeight weight, void *ctx);

/* Params.env_rotation and the cos and sin that kernels/light/env.h turns by,
 * computed here in double so that every device reads the same floats. */
void lights_set_env_rotation(Params *p, float radians);


/* cdf[0..n] from n non-negative weights (summed in double). With a zero
 * total the table is uniform if `uniform_if_empty`, else all zeros (which
 * sample_cdf treats as empty). Returns the total. */
double cdf_build(float *cdf, const double *w, uint32_t n, int uniform_if_empty);

#endif
