/* light_tables.c — builds the light tables of kernels/light/lights.h.
 *
 * Sums run in double so a few hundred thousand emitters or a large sky
 * image still give a monotone CDF ending exactly at 1. Tables with nothing
 * to weigh (an all-black row or image, zero-area portals) fall back to a
 * uniform table or an empty one that sample_cdf refuses, never to NaN. */
#include "prepare/light_tables.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "light/lights.h"
#include "scene/emit_mask.h"

static float tri_area(V3 p0, V3 p1, V3 p2)
{
	return 0.5f * v3_len(v3_cross(v3_sub(p1, p0), v3_sub(p2, p0)));
}

double cdf_build(float *cdf, const double *w, uint32_t n, int uniform_if_empty)
{
	double total = 0.0;
	for (uint32_t i = 0; i < n; i++)
		total += w[i];
	cdf[0] = 0.0f;
	double acc = 0.0;
	for (uint32_t i = 0; i < n; i++) {
		acc += w[i];
		if (total > 0.0)
			cdf[i + 1] = (float)(acc / total);
		else
			cdf[i + 1] = uniform_if_empty ? (float)(i + 1) / (float)n : 0.0f;
	}
	if (n > 0 && (total > 0.0 || uniform_if_empty))
		cdf[n] = 1.0f;
	return total;
}

/* Emissive textures: a triangle is split into 4^level cells of equal area
 * (kernels/light/lights.h) so that a cell covers at most TEXELS_PER_CELL texels,
 * and each cell is chosen by its own power; dark parts of a texture (and
 * holes that alpha cuts) are then never sampled. Levels are capped per triangle and lowered for all
 * where the scene would pass CELL_BUDGET cells. */
#define TEXELS_PER_CELL 0.5
#define MAX_LEVEL 7
#define CELL_BUDGET (1u << 21)

static int cell_level(const SceneView *v, uint32_t i, int tex, int cap)
{
	double x[3], y[3];
	scene_tri_texel_coords(v, i, tex, x, y);
	double texels = 0.5 * fabs((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]));
	int level = 0;
	while (level < cap && (double)(1u << (2 * level)) * TEXELS_PER_CELL < texels)
		level++;
	return level;
}

/* Mean emitted luminance over cell c of triangle i, from four points
 * (the centroid and three toward the corners) of its bilinear texture. */
static double cell_luminance(const SceneView *v, uint32_t i, int level, int c)
{
	static const float w[4][3] = {{1.0f / 3, 1.0f / 3, 1.0f / 3},
				      {2.0f / 3, 1.0f / 6, 1.0f / 6},
				      {1.0f / 6, 2.0f / 3, 1.0f / 6},
				      {1.0f / 6, 1.0f / 6, 2.0f / 3}};
	const Tri *t = &v->tris[i];
	float b1[3] = {0.0f, 1.0f, 0.0f}, b2[3] = {0.0f, 0.0f, 1.0f};
	if (level)
		emitter_cell_corners(level, c, b1, b2);
	double sum = 0.0;
	for (int k = 0; k < 4; k++) {
		float u = w[k][0] * b1[0] + w[k][1] * b1[1] + w[k][2] * b1[2];
		float vv = w[k][0] * b2[0] + w[k][1] * b2[1] + w[k][2] * b2[2];
		V3 p = v3_add(t->p0, v3_add(v3_scale(v3_sub(t->p1, t->p0), u), v3_scale(v3_sub(t->p2, t->p0), vv)));
		sum += v3_lum(emitter_emission(v, (int)i, p));
	}
	return sum / 4.0;
}

static ajar_status build_emitters(const Scene *s, Tri *tris, const TriShade *shade, const TriExtra *extra,
				  uint32_t ntris, const Material *mats, LightTables *out)
{
	SceneView v;
	memset(&v, 0, sizeof v);
	v.tris = tris;
	v.shade = shade;
	v.extra = extra;
	v.materials = mats;
	v.textures = s->textures;
	v.texels = s->texels;
	signed char *level = calloc(ntris ? ntris : 1, 1);
	if (!level)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory for %u triangles", ntris);
	EmitMask mask;
	if (emit_mask_build(&mask, s->textures, s->ntextures, s->texels, mats, s->nmaterials) != AJAR_OK) {
		free(level);
		return AJAR_ERROR_OUT_OF_MEMORY;
	}
	/* Which triangles emit, and each one's finest level. */
	for (uint32_t i = 0; i < ntris; i++) {
		const Tri *t = &tris[i];
		const Material *m = &mats[t->material];
		level[i] = -1;
		if (!(v3_lum(m->emission) > 0.0f) || !(tri_area(t->p0, t->p1, t->p2) > 0.0f))
			continue;
		if (m->emissive_tex && !emit_mask_can_emit(&mask, &v, i, m->emissive_tex - 1))
			continue;
		/* Cells as fine as the texture that varies the emission: the
		 * emissive one, else, where alpha cuts holes, the base colour's. */
		int tex = m->emissive_tex ? m->emissive_tex - 1 : (t->flags & TRI_ALPHA) ? m->base_tex : -1;
		level[i] = (signed char)(tex >= 0 ? cell_level(&v, i, tex, MAX_LEVEL) : 0);
	}
	emit_mask_free(&mask);
	uint64_t n;
	for (int cap = MAX_LEVEL;; cap--) {
		n = 0;
		for (uint32_t i = 0; i < ntris; i++)
			if (level[i] >= 0) {
				if (level[i] > cap)
					level[i] = (signed char)cap;
				n += 1u << (2 * level[i]);
			}
		if (n <= CELL_BUDGET || cap == 0)
			break;
	}
	if (n > UINT32_MAX / 2) {
		free(level);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %llu emitters are too many", s->source, (unsigned long long)n);
	}
	out->nemitters = (uint32_t)n;
	out->emitters = calloc(n ? n : 1, sizeof(Emitter));
	out->emitter_cdf = calloc((size_t)n + 1, sizeof(float));
	double *power = calloc(n ? n : 1, sizeof(double));
	if (!out->emitters || !out->emitter_cdf || !power) {
		free(power);
		free(level);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory for %llu emitters", (unsigned long long)n);
	}
	/* Tri.emitter is written only where it changes: the triangles are the
	 * scene's, shared with renderers that may be reading them (their
	 * values are the same, scene_share.h). */
	uint32_t k = 0;
	for (uint32_t i = 0; i < ntris; i++) {
		Tri *t = &tris[i];
		int emitter = level[i] < 0 ? -1 : (int)k;
		if (t->emitter != emitter)
			t->emitter = emitter;
		if (level[i] < 0)
			continue;
		const Material *m = &mats[t->material];
		int cells = 1 << (2 * level[i]);
		float area = tri_area(t->p0, t->p1, t->p2);
		for (int c = 0; c < cells; c++, k++) {
			Emitter *e = &out->emitters[k];
			e->tri = (int)i;
			e->area = area / (float)cells;
			e->cell = EMITTER_CELL(level[i], c);
			/* One-sided Lambertian emitter: exitance pi L over the area. */
			double lum = m->emissive_tex || (t->flags & TRI_ALPHA) ? cell_luminance(&v, i, level[i], c)
									       : v3_lum(m->emission);
			power[k] = (double)e->area * AJAR_PI * lum;
		}
	}
	out->emitter_power = (float)cdf_build(out->emitter_cdf, power, (uint32_t)n, 0);
	for (uint32_t j = 0; j < n; j++)
		out->emitters[j].pdf_select = out->emitter_cdf[j + 1] - out->emitter_cdf[j];
	free(power);
	free(level);
	return AJAR_OK;
}

/* Pixels x strength, then the marginal and conditional CDFs of
 * luminance x sin(theta) at each row's centre (kernels/base/types.h). Returns
 * the average radiance luminance over the sphere in *avg_lum. */
/* The share of a sky image's power (luminance x solid angle) that its
 * brightest texels covering SUN_SOLID_ANGLE_SHARE of the sphere carry: a
 * compact sun's. window-room-forest's sky 0.13, window-room-sunset's
 * (3 degrees up, reddened) 0.03, that forest sky with everything above
 * its 99th percentile clipped (overcast-like) 0.01. The brightest texels
 * are found by a histogram of luminance in 1/16-octave bins below the
 * maximum, the last bin taken in proportion, so the cost is two passes
 * over the image. With a weight per texel the same texels are the sun,
 * and the share is of the weighted power: src/prepare/portal_flux.c weighs by
 * what comes in through the portals, and src/prepare/prepare.c reads that for
 * portal's light subpaths. */
#define SUN_SOLID_ANGLE_SHARE 0.001
#define SUN_BINS 640 /* 40 octaves */
float env_sun_share_weighted(const float *pix, uint32_t w, uint32_t h, EnvTexelWeight weight, void *ctx)
{
	double sa[SUN_BINS] = {0}, pw[SUN_BINS] = {0}, sa_all = 0.0, pw_all = 0.0;
	float max_lum = 0.0f;
	for (size_t i = 0; i < (size_t)w * h; i++)
		max_lum = fmaxf(max_lum, v3_lum(v3(pix[3 * i], pix[3 * i + 1], pix[3 * i + 2])));
	if (!(max_lum > 0.0f))
		return 0.0f;
	double top = log2(max_lum);
	for (uint32_t y = 0; y < h; y++) {
		double sin_theta = sin(AJAR_PI * ((double)y + 0.5) / h);
		sa_all += sin_theta * w;
		for (uint32_t x = 0; x < w; x++) {
			const float *p = pix + 3 * ((size_t)y * w + x);
			float lum = v3_lum(v3(p[0], p[1], p[2]));
			if (!(lum > 0.0f))
				continue;
			double b = (top - log2(lum)) * 16.0;
			int k = b < SUN_BINS - 1 ? (int)b : SUN_BINS - 1;
			double p_t = weight ? lum * sin_theta * weight(x, y, ctx) : lum * sin_theta;
			sa[k] += sin_theta;
			pw[k] += p_t;
			pw_all += p_t;
		}
	}
	double need = SUN_SOLID_ANGLE_SHARE * sa_all, got = 0.0;
	for (int k = 0; k < SUN_BINS && need > 0.0; k++) {
		double take = sa[k] < need ? 1.0 : need / sa[k];
		got += take * pw[k];
		need -= take * sa[k];
	}
	return pw_all > 0.0 ? (float)(got / pw_all) : 0.0f;
}

static ajar_status build_env_image(const Scene *s, LightTables *out, double *avg_lum)
{
	uint32_t w = s->env_width, h = s->env_height;
	out->nenv = ENV_FLOATS((size_t)w, (size_t)h);
	out->env = malloc(sizeof(float) * out->nenv);
	double *wt = malloc(sizeof(double) * (w > h ? w : h));
	double *rows = malloc(sizeof(double) * h);
	if (!out->env || !wt || !rows) {
		free(wt);
		free(rows);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for a %ux%u environment",
			       s->source, w, h);
	}
	float *pix = out->env + ENV_PIXELS(w, h);
	for (size_t i = 0; i < (size_t)w * h * 3; i++)
		pix[i] = s->env_rgb[i] * s->env_strength;
	double sum = 0.0;
	for (uint32_t y = 0; y < h; y++) {
		double sin_theta = sin(AJAR_PI * ((double)y + 0.5) / h);
		for (uint32_t x = 0; x < w; x++) {
			const float *p = pix + 3 * ((size_t)y * w + x);
			float lum = v3_lum(v3(p[0], p[1], p[2]));
			wt[x] = lum > 0.0f ? lum * sin_theta : 0.0;
		}
		float *cond = out->env + ENV_CONDITIONAL(w, h) + (size_t)y * (w + 1);
		/* An all-black row is never picked (its marginal weight is 0),
		 * but a uniform table keeps it well-formed. */
		rows[y] = cdf_build(cond, wt, w, 1);
		sum += rows[y];
	}
	cdf_build(out->env + ENV_MARGINAL(w, h), rows, h, 1);
	/* Each texel spans (2 pi / w) x (pi / h) in (phi, theta). */
	*avg_lum = sum * (2.0 * AJAR_PI / w) * (AJAR_PI / h) / (4.0 * AJAR_PI);
	free(wt);
	free(rows);
	return AJAR_OK;
}

static ajar_status build_portals(PortalTri *portals, uint32_t n, LightTables *out)
{
	out->nportals = n;
	out->portal_cdf = calloc((size_t)n + 1, sizeof(float));
	double *area = calloc(n ? n : 1, sizeof(double));
	if (!out->portal_cdf || !area) {
		free(area);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory for %u portal triangles", n);
	}
	for (uint32_t i = 0; i < n; i++) {
		portals[i].area = tri_area(portals[i].p0, portals[i].p1, portals[i].p2);
		area[i] = portals[i].area;
	}
	cdf_build(out->portal_cdf, area, n, 0);
	for (uint32_t i = 0; i < n; i++) {
		portals[i].pdf_select = out->portal_cdf[i + 1] - out->portal_cdf[i];
		portals[i].side_plus = 0.5f; /* until src/prepare/portal_flux.c has looked */
		portals[i].env_side = 0;
	}
	free(area);
	return AJAR_OK;
}

/* The area through which the environment's light is counted for its share
 * of the light choice, the same as a directional light's (punctual_power),
 * so that the two compare what reaches the scene: with portals, the sky
 * lights the scene through them (next-event estimation samples it through
 * them, env_portal.h), pi L over one side of their area; without, the disk
 * of the scene's radius that light subpaths from the environment start
 * from (design.md). Counted over the whole disk, a sky under a sun lamp
 * took 99.1% of the choice on window-room-sun (pi R^2 = 25 m^2 against a
 * 0.64 m^2 window) and the sun 0.9% (now 74% and 26%), where the two bring
 * comparable light into the room (kernels/light/README.md, "The light choice"). */
static double env_cross_section(const PortalTri *portals, uint32_t nportal_tris, float scene_radius)
{
	double a = 0.0;
	for (uint32_t j = 0; j < nportal_tris; j++)
		a += (double)portals[j].area;
	return nportal_tris > 0 ? a : AJAR_PI * (double)scene_radius * scene_radius;
}

/* glTF's photometric units to Ajar's radiometric ones: Blender's glTF
 * importer's default ("Standard") converts at 683 lm/W, so a scene
 * exported from Blender renders alike in both. */
#define LUMENS_PER_WATT 683.0

/* Power estimate of a punctual light, for its share of the light choice:
 * any positive value is unbiased (the densities read the table), it only
 * decides where samples go. A directional light: its irradiance over the
 * cross-section its light subpaths start from (the portals' projected
 * area, or the disk of the scene's radius). */
static double punctual_power(const PunctualLight *l, const PortalTri *portals, uint32_t nportal_tris)
{
	double lum = v3_lum(l->intensity);
	if (l->type == LIGHT_POINT)
		return 4.0 * AJAR_PI * lum;
	if (l->type == LIGHT_SPOT)
		return 2.0 * AJAR_PI * (1.0 - (double)l->cos_outer) * lum;
	double a = 0.0;
	for (uint32_t j = 0; j < nportal_tris; j++)
		a += (double)portals[j].area * fabs((double)v3_dot(portals[j].n, l->dir));
	if (nportal_tris == 0)
		a = AJAR_PI * (double)l->disk_radius * l->disk_radius;
	return lum * a;
}

/* The punctual lights in device form, and emitter_cdf rebuilt over the
 * emitters and then the lights, by power. */
static ajar_status build_punctual(const Scene *s, const PortalTri *portals, uint32_t nportal_tris, float scene_radius,
				  LightTables *out)
{
	uint32_t ne = out->nemitters, nl = s->nlights;
	out->nlights = nl;
	out->lights = calloc(nl ? nl : 1, sizeof(PunctualLight));
	if (!out->lights)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory for %u lights", nl);
	if (nl == 0)
		return AJAR_OK;
	float *cdf = calloc((size_t)ne + nl + 1, sizeof(float));
	double *power = calloc((size_t)ne + nl, sizeof(double));
	if (!cdf || !power) {
		free(cdf);
		free(power);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory for %u lights", nl);
	}
	/* The emitters' (textured) powers, as build_emitters weighed them. */
	for (uint32_t k = 0; k < ne; k++)
		power[k] = (double)out->emitters[k].pdf_select * out->emitter_power;
	double lp = 0.0;
	for (uint32_t i = 0; i < nl; i++) {
		const ajar_light *a = &s->lights[i];
		PunctualLight *l = &out->lights[i];
		double k = 1.0 / LUMENS_PER_WATT * a->intensity;
		l->type = a->type == AJAR_LIGHT_DIRECTIONAL ? LIGHT_DIRECTIONAL
			  : a->type == AJAR_LIGHT_SPOT      ? LIGHT_SPOT
							    : LIGHT_POINT;
		l->pos = v3(a->position[0], a->position[1], a->position[2]);
		l->dir = v3(a->direction[0], a->direction[1], a->direction[2]);
		l->intensity = v3((float)(k * a->color[0]), (float)(k * a->color[1]), (float)(k * a->color[2]));
		l->range = l->type == LIGHT_DIRECTIONAL ? 0.0f : a->range;
		l->cos_outer = -1.0f;
		l->cone_scale = 0.0f;
		if (l->type == LIGHT_SPOT) {
			double co = cos((double)a->outer_cone), ci = cos((double)a->inner_cone);
			l->cos_outer = (float)co;
			l->cone_scale = (float)(1.0 / fmax(0.001, ci - co));
		}
		l->disk_radius = scene_radius;
		power[ne + i] = punctual_power(l, portals, nportal_tris);
		lp += power[ne + i];
	}
	cdf_build(cdf, power, ne + nl, 0);
	for (uint32_t k = 0; k < ne; k++)
		out->emitters[k].pdf_select = cdf[k + 1] - cdf[k];
	for (uint32_t i = 0; i < nl; i++)
		out->lights[i].pdf_select = cdf[ne + i + 1] - cdf[ne + i];
	free(out->emitter_cdf);
	out->emitter_cdf = cdf;
	out->light_power = (float)lp;
	free(power);
	return AJAR_OK;
}

ajar_status lights_build(const Scene *s, Tri *tris, const TriShade *shade, const TriExtra *extra, uint32_t ntris, const Material *mats,
			 PortalTri *portals, uint32_t nportal_tris, V3 scene_center, float scene_radius,
			 LightTables *out)
{
	ajar_status st;
	memset(out, 0, sizeof(*out));
	if ((st = build_emitters(s, tris, shade, extra, ntris, mats, out)) != AJAR_OK ||
	    (st = build_portals(portals, nportal_tris, out)) != AJAR_OK ||
	    (st = build_punctual(s, portals, nportal_tris, scene_radius, out)) != AJAR_OK) {
		lights_free(out);
		return st;
	}

	double avg_lum = 0.0;
	if (s->env_type == ENV_IMAGE) {
		if ((st = build_env_image(s, out, &avg_lum)) != AJAR_OK) {
			lights_free(out);
			return st;
		}
	} else {
		out->env = calloc(1, sizeof(float));
		if (!out->env) {
			lights_free(out);
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "lights: out of memory");
		}
		if (s->env_type == ENV_COLOR)
			avg_lum = fmax(v3_lum(s->env_color), 0.0f);
	}
	out->env_power = (float)(env_cross_section(portals, nportal_tris, scene_radius) * AJAR_PI * avg_lum);

	if (s->env_type == ENV_NONE || !(out->env_power > 0.0f))
		out->env_pdf_select = 0.0f;
	else if (!(out->emitter_power + out->light_power > 0.0f))
		out->env_pdf_select = 1.0f;
	else
		out->env_pdf_select = out->env_power / (out->env_power + out->emitter_power + out->light_power);
	return AJAR_OK;
}

void lights_free(LightTables *t)
{
	free(t->emitters);
	free(t->emitter_cdf);
	free(t->env);
	free(t->portal_cdf);
	free(t->lights);
	memset(t, 0, sizeof(*t));
}

void lights_set_env_rotation(Params *p, float radians)
{
	p->env_rotation = radians;
	p->env_rot_cos = (float)cos((double)radians);
	p->env_rot_sin = (float)sin((double)radians);
}
