/* prepare.c — from Scene to device arrays. Triangles and their shading data
 * are reordered to the BVH's leaf order so a leaf's triangles are
 * contiguous; the light tables are built on the reordered triangles so
 * emitter indices and Tri.emitter agree. */
#include "prepare/prepare.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "device/device.h"
#include "core/error.h"
#include "prepare/portal_flux.h"
#include "prepare/sky_tables.h"

static double seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Whether a hit on triangle t can get a shading normal that bsdf_setup_mr
 * counts as tilted (BSDF_TILTED: |n . ng| < BSDF_TILT_COS, kernels/material/bsdf.h).
 * An interpolated normal is a positive combination of the three vertex
 * normals, so where each unit vertex normal has n . ng >= c on one side,
 * so has the normalized interpolation; c = 0.999995 keeps a margin of
 * 5e-6 over BSDF_TILT_COS (0.99999) for the kernel's rounding. */
static int tri_may_tilt(const Tri *t, const TriShade *sh)
{
	if (t->flags & TRI_TANGENT)
		return 1;
	if (!sh->has_normals)
		return 0;
	V3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0);
	double gx = (double)e1.y * e2.z - (double)e1.z * e2.y, gy = (double)e1.z * e2.x - (double)e1.x * e2.z,
	       gz = (double)e1.x * e2.y - (double)e1.y * e2.x;
	double lg = sqrt(gx * gx + gy * gy + gz * gz);
	if (!(lg > 0.0))
		return 1; /* degenerate: never hit in practice, but not provably flat */
	const V3 *n[3] = {&sh->n0, &sh->n1, &sh->n2};
	int side = 0;
	for (int k = 0; k < 3; k++) {
		double ln = sqrt((double)n[k]->x * n[k]->x + (double)n[k]->y * n[k]->y + (double)n[k]->z * n[k]->z);
		if (!(ln > 0.0) || !isfinite(ln))
			return 1;
		double c = ((double)n[k]->x * gx + (double)n[k]->y * gy + (double)n[k]->z * gz) / (ln * lg);
		int s = c >= 0.999995 ? 1 : (c <= -0.999995 ? -1 : 0);
		if (s == 0 || (side && s != side))
			return 1;
		side = s;
	}
	return 0;
}

/* The DEVICE_OMIT_* features that no triangle or material of the prepared
 * scene uses: alpha tests, tilted shading normals (the bend), textures,
 * TriExtra data. Emitters with textures or alpha count as using them. */
static unsigned kernel_omit(const SceneData *d)
{
	unsigned omit = DEVICE_OMIT_ALPHA | DEVICE_OMIT_BENT_NORMALS | DEVICE_OMIT_TRI_EXTRA;
	for (size_t i = 0; i < d->n_tris; i++) {
		if (d->tris[i].flags & TRI_ALPHA)
			omit &= ~DEVICE_OMIT_ALPHA;
		if (d->tris[i].flags & (TRI_EXTRA | TRI_TANGENT))
			omit &= ~DEVICE_OMIT_TRI_EXTRA;
		if ((omit & DEVICE_OMIT_BENT_NORMALS) && tri_may_tilt(&d->tris[i], &d->shade[i]))
			omit &= ~DEVICE_OMIT_BENT_NORMALS;
	}
	int textured = 0;
	for (size_t i = 0; i < d->n_materials; i++) {
		const Material *m = &d->materials[i];
		textured |= m->base_tex >= 0 || m->mr_tex || m->emissive_tex || m->normal_tex;
	}
	if (!textured)
		omit |= DEVICE_OMIT_TEXTURES;
	return omit;
}

static ajar_status setup_camera(const Scene *s, const PrepareOptions *o, Camera *c)
{
	V3 pos, fwd, up;
	float yfov;
	scene_camera(s, &pos, &fwd, &up, &yfov);
	V3 right = v3_cross(fwd, up);
	if (!(v3_len2(right) > 1e-20f) || !(yfov > 0.0f && yfov < 3.1f))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: camera: degenerate orientation or field of view",
			       s->source);
	memset(c, 0, sizeof *c);
	c->pos = pos;
	c->forward = v3_norm(fwd);
	c->right = v3_norm(right);
	c->up = v3_cross(c->right, c->forward);
	c->tan_half_fov_y = tanf(0.5f * yfov);
	c->aspect = (float)o->width / (float)o->height;
	c->width = (int)o->width;
	c->height = (int)o->height;
	return AJAR_OK;
}

/* A rate in (0, 1] from the environment variable `name`, else `dflt`. */
/* Whether a point or spot light lies behind a portal as the camera sees
 * it: on the other side of some portal triangle's plane, within its range
 * of the triangle. Its light then reaches the camera's side through the
 * opening, as an emitter's in door-ajar does, and the intermediate
 * subpaths carry it (kernels/sky_measurements.md, "Where light subpaths
 * come in, portal is bdpt"). A plane test, not a visibility test: it
 * only chooses the strategies, never the image's expectation. */
static int lamp_behind_portal(const SceneData *d, V3 camera)
{
	for (uint32_t i = 0; i < d->lights.nlights; i++) {
		const PunctualLight *l = &d->lights.lights[i];
		if (l->type == LIGHT_DIRECTIONAL)
			continue;
		for (size_t k = 0; k < d->n_portals; k++) {
			const PortalTri *t = &d->portals[k];
			float side_cam = v3_dot(t->n, v3_sub(camera, t->p0)), side_l = v3_dot(t->n, v3_sub(l->pos, t->p0));
			if (!(side_cam * side_l < 0.0f))
				continue;
			float near = fminf(v3_len(v3_sub(l->pos, t->p0)),
					   fminf(v3_len(v3_sub(l->pos, t->p1)), v3_len(v3_sub(l->pos, t->p2))));
			if (l->range <= 0.0f || fabsf(side_l) <= l->range || near <= l->range)
				return 1;
		}
	}
	return 0;
}

/* Cells a side of the planes' sky tables (kernels/light/portal_sky.h). With 128
 * cells (1.4 degrees at the centre) a sun of a sky of 2048 columns or more
 * (0.53 degrees, a few texels) covers a fraction of its cell, and pt's
 * next-event samples drawn into that cell mostly miss it: 512 cells (0.35
 * degrees) halved pt's variance per sample there (2k and 4k skies,
 * window-room and living-room: 1.7-2x less variance x time), and 256 gave
 * it 3-22% under the shipped 1k skies. bdpt and portal keep 128: their
 * light subpaths bring the sun in by the image's own full-resolution table,
 * their MIS weights read the tables many times, and finer ones gave them
 * 1-6% less variance for up to 30% more time (kernels/sky_measurements.md,
 * "Sharper sky tables for pt"). AJAR_SKY_RES = 128, 256 or 512 sets it for
 * any integrator, for comparisons. */
static int sky_table_res(const Scene *s, int integrator)
{
	int res = 128;
	if (integrator == INTEGRATOR_PT && s->env_type == ENV_IMAGE && s->nportal_tris > 0)
		res = s->env_width >= 2048 ? 512 : 256;
	const char *v = getenv("AJAR_SKY_RES");
	if (v) {
		if (strcmp(v, "128") == 0 || strcmp(v, "256") == 0 || strcmp(v, "512") == 0)
			res = atoi(v);
		else
			log_msg(AJAR_LOG_WARNING, "AJAR_SKY_RES='%s' is not 128, 256 or 512; ignored", v);
	}
	return res;
}

static float env_rate(const char *name, float dflt)
{
	const char *v = getenv(name);
	if (!v)
		return dflt;
	char *end;
	float r = strtof(v, &end);
	if (end != v && *end == '\0' && r > 0.0f && r <= 1.0f)
		return r;
	log_msg(AJAR_LOG_WARNING, "%s='%s' is not in (0, 1]; ignored", name, v);
	return dflt;
}

ajar_status prepare_scene(const Scene *s, const PrepareOptions *o, SceneData *d)
{
	ajar_status st;
	uint32_t n = s->ntris;
	memset(d, 0, sizeof *d);
	if (n == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: the scene has no triangles", s->source);
	if (s->nmaterials == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: the scene has no materials", s->source);

	double t0 = seconds();
	if ((st = bvh_build(s->tris, n, &d->bvh)) != AJAR_OK)
		return st;
	d->bvh_seconds = seconds() - t0;
	d->nodes = d->bvh.nodes;
	d->n_nodes = d->bvh.nnodes;

	d->tris = malloc(sizeof *d->tris * n);
	d->shade = malloc(sizeof *d->shade * n);
	d->n_extra = s->extra ? n : 1; /* one unused entry, so a device buffer exists */
	d->extra = calloc(d->n_extra, sizeof *d->extra);
	d->params = calloc(1, sizeof *d->params);
	d->portals = malloc(sizeof *d->portals * (s->nportal_tris ? s->nportal_tris : 1));
	if (!d->tris || !d->shade || !d->params || !d->portals || !d->extra) {
		prepare_free(d);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory preparing %u triangles", s->source, n);
	}
	for (uint32_t i = 0; i < n; i++) {
		d->tris[i] = s->tris[d->bvh.order[i]];
		d->shade[i] = s->shade[d->bvh.order[i]];
		if (s->extra)
			d->extra[i] = s->extra[d->bvh.order[i]];
	}
	d->n_tris = d->n_shade = n;
	if (s->nportal_tris)
		memcpy(d->portals, s->portals, sizeof *d->portals * s->nportal_tris);
	d->n_portals = s->nportal_tris;
	d->materials = s->materials;
	d->n_materials = s->nmaterials;
	d->textures = s->textures;
	d->n_textures = s->ntextures;
	d->texels = s->texels;
	d->n_texels = s->ntexels;
	d->kernel_omit = kernel_omit(d);

	scene_bounds(s, &d->bmin, &d->bmax);
	V3 center = v3_scale(v3_add(d->bmin, d->bmax), 0.5f);
	float radius = 0.5f * v3_len(v3_sub(d->bmax, d->bmin)) * 1.001f + 1e-4f;
	if ((st = lights_build(s, d->tris, d->shade, d->extra, n, s->materials, d->portals, s->nportal_tris, center, radius,
			       &d->lights)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	d->emitters = d->lights.emitters;
	d->n_emitters = d->lights.nemitters;
	d->emitter_cdf = d->lights.emitter_cdf;
	d->n_emitter_cdf = d->lights.nemitters + d->lights.nlights + 1; /* sample_cdf reads cdf[n] even for n = 0 */
	d->punctual = d->lights.lights;
	d->n_punctual = d->lights.nlights ? d->lights.nlights : 1;
	d->env = d->lights.env;
	d->n_env = d->lights.nenv;
	d->portal_cdf = d->lights.portal_cdf;
	d->n_portal_cdf = d->lights.nportals + 1;

	Params *p = d->params;
	d->n_params = 1;
	if ((st = setup_camera(s, o, &p->camera)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	p->num_tris = (int)n;
	p->num_emitters = (int)d->lights.nemitters;
	p->num_lights = (int)d->lights.nlights;
	p->light_power = d->lights.light_power;
	p->num_portals = (int)s->nportal_tris;
	p->num_textures = (int)s->ntextures;
	p->env_type = s->env_type;
	p->env_width = (int)s->env_width;
	p->env_height = (int)s->env_height;
	p->env_strength = s->env_strength;
	lights_set_env_rotation(p, s->env_rotation);
	p->env_color = s->env_color;
	p->env_pdf_select = d->lights.env_pdf_select;
	p->scene_center = center;
	p->scene_radius = radius;
	p->max_depth = (int)o->max_depth;
	p->rr_depth = 2;
	/* Without portals the portal integrator is bdpt, sample for sample. */
	p->integrator = o->integrator == INTEGRATOR_PORTAL && s->nportal_tris == 0 ? INTEGRATOR_BDPT : o->integrator;
	p->seed = o->seed;
	p->min_depth = (int)o->min_depth;
	p->strategy_len = (int)o->strategy_len;
	p->strategy_unweighted = o->strategy_unweighted;
	/* What lies behind each side of the portals, with the kernels' own
	 * tracing run here on the finished light tables. */
	SceneView view;
#define PREPARE_VIEW(type, name) view.name = d->name;
	AJAR_SCENE_BUFFERS(PREPARE_VIEW)
#undef PREPARE_VIEW
	if ((st = portal_flux_build(&view, d->portals, (uint32_t)d->n_portals, d->portal_cdf)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	/* Light subpaths from a constant sky start on a disk as wide as the
	 * scene and rarely find the way in through an opening; where such a
	 * sky is the only light, the intermediate subpaths (which start on the
	 * portals) do their work, and the portal integrator leaves them out.
	 * A sky image's light subpaths start on the portals (kernels/light/lights.h,
	 * line_sample): measured better per CPU second on window-room-forest
	 * and living-room-forest, whose sky has a compact sun, and on
	 * window-room-sunset (a low, dim sun), and even with portal's own
	 * strategies under that forest sky with its sun clipped
	 * (kernels/sky_measurements.md, "Sky light subpaths through the
	 * portals" and "Weights from tails"), so on for sky images whose
	 * brightest 0.1% of solid angle carries at least SKY_SUN_SHARE of the
	 * sky light that comes in through the portals (portal_flux.c,
	 * portal_sun_share: 0.24, 0.066 and 0.020 there; 0 for a sun behind
	 * the wall, where they were even with none). */
	/* Light subpaths from a sky image start on lines through the portals
	 * (kernels/light/lights.h, line_sample); their directions follow the light
	 * that comes in through them (portal_sky_lines_build). AJAR_SKY_LINES=0
	 * keeps the image's own distribution, for comparisons. */
	const char *lines = getenv("AJAR_SKY_LINES");
	p->env_lines = 0;
	if (s->env_type == ENV_IMAGE && s->nportal_tris > 0 && !(lines && strcmp(lines, "0") == 0)) {
		if ((st = portal_sky_lines_build(p, d->portals, (uint32_t)d->n_portals, &d->lights.env,
						 &d->lights.nenv)) != AJAR_OK) {
			prepare_free(d);
			return st;
		}
		d->env = d->lights.env;
		view.env = d->env;
		d->n_env = d->lights.nenv;
		p->env_lines = 1;
	}
	/* Whether a sky image's sun shines in through the portals: read by
	 * portal's light subpaths and by the MIS heuristic's default. */
	int sun_in = 0;
	if (p->integrator != INTEGRATOR_PT && s->env_type == ENV_IMAGE && s->nportal_tris > 0 &&
	    (p->integrator == INTEGRATOR_PORTAL || o->mis == AJAR_MIS_AUTO)) {
		d->sun_share_portals = portal_sun_share(&view, d->portals, (uint32_t)d->n_portals);
		sun_in = d->sun_share_portals >= SKY_SUN_SHARE;
	}
	int sky_image_lines = p->integrator == INTEGRATOR_PORTAL && sun_in;
	/* The MIS heuristic. AJAR_MIS_AUTO takes the balance heuristic where a
	 * sky image's sun shining in through the portals is the only light: there
	 * it lowered bdpt's and portal's variance per sample by 9-20% at the same
	 * time on every sky scene with a sun, three pairs of seeds each, while
	 * lamps and constant skies went either way, up to 34% worse
	 * (kernels/sky_measurements.md, "The balance heuristic under a sun");
	 * power elsewhere, as before. */
	p->mis = o->mis;
	_Static_assert(AJAR_MIS_POWER == MIS_POWER && AJAR_MIS_BALANCE == MIS_BALANCE, "the kernels read ajar_mis");
	if (o->mis == AJAR_MIS_AUTO) {
		p->mis = sun_in && p->num_emitters == 0 && p->num_lights == 0 ? MIS_BALANCE : MIS_POWER;
		if (p->mis == MIS_BALANCE)
			log_msg(AJAR_LOG_INFO, "%s: a sky image's sun shines in through the portals; MIS by the balance heuristic",
				s->source ? s->source : "scene");
	}
	p->light_paths = p->integrator != INTEGRATOR_PORTAL || p->num_emitters > 0 || p->num_lights > 0 || sky_image_lines;
	/* The intermediate strategies in use (kernels/integrator/portal.h), chosen by
	 * measurement (kernels/README.md, "portal"). Where the sky is the only
	 * light, next-event estimation through the portals takes the direct
	 * light, and short halves and eye parts of at most 3 vertices do best;
	 * with emitters behind an opening (door-ajar) the intermediate
	 * subpaths carry the indirect light on both sides of it, with halves
	 * and eye parts as long as the depth allows. AJAR_PORTAL_SET="s,s',t'[,t[,light paths]]"
	 * overrides it for experiments, e.g. "32,32,32,33,1" for all of them. */
	/* Punctual lights without emitters (kernels/punctual.md, "Punctual
	 * lights"): their light subpaths are kept (a sun's start on the
	 * portals and find its patch), and the intermediate subpaths, which
	 * reach a delta light only by next-event estimation, carry the sky, so
	 * the sky's set and rate (a sky image's light subpaths take the same):
	 * on window-room-sun the long halves at rate 1 cost 3x in time for no
	 * less noise, on window-room-lamp (a lamp on the camera's side) 3.5x
	 * bdpt's inefficiency. A point or spot light behind a portal counts as
	 * an emitter: in door-ajar with a point lamp for its emitter the long
	 * halves at rate 1 did 1.5x better than bdpt and 1.25x better than the
	 * sky's set. */
	int long_set = p->light_paths && (p->integrator != INTEGRATOR_PORTAL || p->num_emitters > 0 ||
					  lamp_behind_portal(d, p->camera.pos));
	p->portal_s_max = 1;
	p->portal_sp_max = long_set ? AJAR_BIDIR_MAX_DEPTH : 2;
	p->portal_tp_max = long_set ? AJAR_BIDIR_MAX_DEPTH : 1;
	p->portal_t_max = long_set ? 1 << 20 : 3; /* any t, or 3 */
	const char *set = getenv("AJAR_PORTAL_SET");
	int set_given = 0;
	if (set) {
		int v[5] = {p->portal_s_max, p->portal_sp_max, p->portal_tp_max, p->portal_t_max, p->light_paths};
		int nset = sscanf(set, "%d,%d,%d,%d,%d", &v[0], &v[1], &v[2], &v[3], &v[4]);
		if (nset >= 3 && v[0] >= 0 && v[1] >= 1 && v[2] >= 1 && v[3] >= 1) {
			p->portal_s_max = v[0];
			p->portal_sp_max = v[1];
			p->portal_tp_max = v[2];
			p->portal_t_max = v[3];
			p->light_paths = v[4] != 0;
			set_given = 1;
		} else {
			log_msg(AJAR_LOG_WARNING, "AJAR_PORTAL_SET='%s' is not s,s',t'[,t[,light paths]]; ignored", set);
		}
	}
	if (!p->light_paths && p->portal_s_max > 1)
		p->portal_s_max = 1; /* larger s needs light subpaths */
	/* Where light subpaths bring the light in through the openings (a sky
	 * image with a sun, punctual lights without emitters), the sky's
	 * intermediate strategies carry under 1.5% of the image, and the union
	 * weights of every path that crosses a portal cost 1.1-1.3x bdpt's time
	 * per sample for the same variance per sample: portal renders as bdpt
	 * there, sample for sample (kernels/sky_measurements.md, "Where light
	 * subpaths come in, portal is bdpt"). An explicit AJAR_PORTAL_SET keeps
	 * the intermediate subpaths. */
	p->bdpt_conn = 0;
	if (p->integrator == INTEGRATOR_PORTAL && p->light_paths && !long_set && !set_given) {
		/* ... with the strategies other than light tracing joining eye
		 * vertices to the first PORTAL_BDPT_CONN light vertices only
		 * (kernels/mis/mis.h, mis_conn_in_set): the rest cost a third of the
		 * time and lowered no variance on window-room-sunset and -forest
		 * (kernels/sky_measurements.md, "Connections to the first light
		 * vertices"). */
		p->integrator = INTEGRATOR_BDPT;
		p->bdpt_conn = PORTAL_BDPT_CONN;
		log_msg(AJAR_LOG_INFO,
			"%s: light subpaths bring the light in through the portals; portal renders as bdpt, connecting "
			"eye vertices to the first %d light vertices",
			s->source ? s->source : "scene", PORTAL_BDPT_CONN);
	}
	/* AJAR_BDPT_CONN=0, 1 or 2 sets it for bdpt (0: every strategy), for
	 * comparisons and tests. */
	const char *conn = getenv("AJAR_BDPT_CONN");
	if (conn && p->integrator == INTEGRATOR_BDPT) {
		if (strcmp(conn, "0") == 0 || strcmp(conn, "1") == 0 || strcmp(conn, "2") == 0)
			p->bdpt_conn = conn[0] - '0';
		else
			log_msg(AJAR_LOG_WARNING, "AJAR_BDPT_CONN='%s' is not 0, 1 or 2; ignored", conn);
	}
	p->emitter_power = d->lights.emitter_power;
	p->env_power = d->lights.env_power;
	/* Sky images are sampled through the planar portals by their radiance
	 * (kernels/light/portal_sky.h); AJAR_PORTAL_SKY=0 keeps the triangles' solid
	 * angle instead, for comparisons. */
	const char *sky = getenv("AJAR_PORTAL_SKY");
	d->sky_res = o->sky_res ? o->sky_res : sky_table_res(s, p->integrator);
	if (!(sky && strcmp(sky, "0") == 0) &&
	    (st = portal_sky_build(&view, d->portals, (uint32_t)d->n_portals, d->sky_res, &d->portal_planes,
				   &d->n_portal_planes, &d->portal_sky, &d->n_portal_sky)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	p->num_portal_planes = (int)d->n_portal_planes;
	/* How often a pixel sample traces an intermediate subpath (mis.h,
	 * MisPortalSet), chosen by measurement at equal time (kernels/README.md,
	 * "portal"): with next-event estimation through the portals, the sky
	 * needs them seldom; light from emitters behind an opening more often.
	 * AJAR_PORTAL_RATE in (0, 1] overrides it. Layers without MIS weights
	 * (tests) take every intermediate subpath. */
	float rate = long_set ? PORTAL_RATE_EMITTERS : PORTAL_RATE_SKY;
	/* Under a sky image (with a sun), sampled through planar portals, the
	 * <- halves guided by the sky's importance find the sun and the ->
	 * halves the patch it lights: worth a higher rate than a constant sky,
	 * without light subpaths (AJAR_PORTAL_SET=1,2,1,3,0, the default
	 * before they started on the portals). */
	if (!p->light_paths && p->num_portal_planes > 0)
		rate = PORTAL_RATE_SKY_IMAGE;
	p->portal_rate = p->strategy_unweighted ? 1.0f : env_rate("AJAR_PORTAL_RATE", rate);
	if (p->num_emitters == 0 && p->num_lights == 0 && p->env_type == ENV_NONE)
		log_msg(AJAR_LOG_WARNING, "%s: no emissive triangles, no lights and no environment: the image is black",
			s->source);
	return AJAR_OK;
}

void prepare_free(SceneData *d)
{
	/* materials, textures and texels are borrowed from the Scene. */
	free(d->tris);
	free(d->shade);
	free(d->extra);
	free(d->params);
	free(d->portals);
	free(d->portal_planes);
	free(d->portal_sky);
	bvh_free(&d->bvh);
	lights_free(&d->lights);
	memset(d, 0, sizeof *d);
}
