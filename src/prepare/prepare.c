/* prepare.c — from Scene to device arrays. The scene's triangles and their
 * shading data, in the BVH's leaf order so a leaf's triangles are
 * contiguous, are shared, not copied (scene_bvh.c); the light tables are
 * built on them in that order so emitter indices and Tri.emitter agree. */
#include "prepare/prepare.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/error.h"
#include "prepare/found_portals.h"
#include "prepare/portal_slide.h"
#include "prepare/pane_planes.h"
#include "prepare/policy.h"
#include "prepare/portal_flux.h"
#include "prepare/scene_bvh.h"
#include "prepare/sky_tables.h"

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

/* The KERNEL_OMIT_* features that no triangle or material of the prepared
 * scene uses: alpha tests, tilted shading normals (the bend), textures,
 * TriExtra data, panes, the BSDF's layers (sheen, clear coat, specular
 * colour) and anisotropy. Emitters with textures or alpha count as using
 * them. */
static unsigned kernel_omit(const SceneData *d)
{
	unsigned omit = KERNEL_OMIT_ALPHA | KERNEL_OMIT_BENT_NORMALS | KERNEL_OMIT_TRI_EXTRA | KERNEL_OMIT_PANES |
			KERNEL_OMIT_LAYERS | KERNEL_OMIT_ANISOTROPY;
	if (!d->n_instances)
		omit |= KERNEL_OMIT_INSTANCES;
	for (size_t i = 0; i < d->n_tris; i++) {
		if (d->tris[i].flags & TRI_ALPHA)
			omit &= ~KERNEL_OMIT_ALPHA;
		if (d->tris[i].flags & TRI_PANE)
			omit &= ~KERNEL_OMIT_PANES;
		if (d->tris[i].flags & (TRI_EXTRA | TRI_TANGENT))
			omit &= ~KERNEL_OMIT_TRI_EXTRA;
		if ((omit & KERNEL_OMIT_BENT_NORMALS) && tri_may_tilt(&d->tris[i], &d->shade[i]))
			omit &= ~KERNEL_OMIT_BENT_NORMALS;
	}
	int textured = 0;
	for (size_t i = 0; i < d->n_materials; i++) {
		const Material *m = &d->materials[i];
		textured |= m->base_tex >= 0 || m->mr_tex || m->emissive_tex || m->normal_tex || m->transmission_tex ||
			    m->specular_tex || m->specular_color_tex || m->sheen_color_tex || m->sheen_rough_tex ||
			    m->clearcoat_tex || m->clearcoat_rough_tex || m->clearcoat_normal_tex || m->anisotropy_tex;
		if ((m->flags & MATERIAL_TINTED) || m->sheen_color.x > 0.0f || m->sheen_color.y > 0.0f ||
		    m->sheen_color.z > 0.0f || m->clearcoat > 0.0f)
			omit &= ~KERNEL_OMIT_LAYERS;
		if (m->anisotropy > 0.0f)
			omit &= ~KERNEL_OMIT_ANISOTROPY;
	}
	if (!textured)
		omit |= KERNEL_OMIT_TEXTURES;
	return omit;
}

static ajar_status setup_camera(const Scene *s, uint32_t width, uint32_t height, Camera *c)
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
	c->aspect = (float)width / (float)height;
	c->width = (int)width;
	c->height = (int)height;
	return AJAR_OK;
}

/* Whether a point or spot light lies behind a portal as the camera sees
 * it: on the other side of some portal triangle's plane, within its range
 * of the triangle. Its light then reaches the camera's side through the
 * opening, as an emitter's in door-ajar does, and the intermediate
 * subpaths carry it (kernels/integrator/README.md, "Where light subpaths
 * come in, portal is bdpt"). The camera's side is the side the camera is
 * on for marked portals, and the side a found portal faces (it faces where
 * the room's rays through it came from: a door's gap found in the jamb's
 * plane has the camera and the lamp on one geometric side). A plane test,
 * not a visibility test: it only chooses the strategies, never the
 * image's expectation. */
static int lamp_behind_portal(const SceneData *d, V3 camera)
{
	int found = d->portal_source == POLICY_PORTALS_FOUND;
	for (uint32_t i = 0; i < d->lights.nlights; i++) {
		const PunctualLight *l = &d->lights.lights[i];
		if (l->type == LIGHT_DIRECTIONAL)
			continue;
		for (size_t k = 0; k < d->n_portals; k++) {
			const PortalTri *t = &d->portals[k];
			float side_cam = found ? 1.0f : v3_dot(t->n, v3_sub(camera, t->p0)),
			      side_l = v3_dot(t->n, v3_sub(l->pos, t->p0));
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

/* A copy of n items of `size` (malloc), or NULL. */
static void *dup_array(const void *p, size_t n, size_t size)
{
	void *q = malloc(n ? n * size : size);
	if (q && n)
		memcpy(q, p, n * size);
	return q;
}

/* What the host's traversal sees of d's geometry. */
static void prepared_view(const SceneData *d, SceneView *v)
{
	memset(v, 0, sizeof *v);
	v->nodes = d->nodes;
	v->tris = d->tris;
	v->shade = d->shade;
	v->extra = d->extra;
	v->materials = d->materials;
	v->textures = d->textures;
	v->texels = d->texels;
	v->instances = d->instances;
	v->params = d->params;
}

/* The portals the render uses (policy_portals): the scene's marked ones
 * (moved out through the tunnels they lie in, portal_slide.c),
 * those the search finds from the camera (portal_find.c, on the BVH just
 * built), or none. d's triangles, shading and materials must be set. */
static ajar_status choose_portals(const Scene *s, const ajar_options *o, SceneData *d)
{
	d->portal_source = policy_portals((int)o->portals, s->nportal_tris);
	uint32_t n = 0;
	if (d->portal_source == POLICY_PORTALS_MARKED) {
		n = s->nportal_tris;
	} else if (d->portal_source == POLICY_PORTALS_FOUND) {
		SceneView v;
		prepared_view(d, &v);
		PortalFindInput in;
		portal_find_input(s, &in);
		/* The flat triangles come first (scene_bvh.c); instances' are
		 * reached through the BVH. */
		ajar_status st = portal_find(&v, scene_flat_triangles(s), &in, &d->found);
		if (st != AJAR_OK)
			return st;
		n = 2 * d->found.count;
		log_msg(AJAR_LOG_INFO, "%s: %s; found %u portal%s over openings in %.2f s (%llu rays)", s->source,
			s->nportal_tris ? "marked portals ignored" : "no portals marked", d->found.count,
			d->found.count == 1 ? "" : "s", d->found.seconds, (unsigned long long)d->found.rays);
	}
	d->portals = malloc(sizeof *d->portals * (n ? n : 1));
	if (!d->portals)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for %u portal triangles", s->source, n);
	if (d->portal_source == POLICY_PORTALS_MARKED)
		memcpy(d->portals, s->portals, sizeof *d->portals * n);
	for (uint32_t i = 0; d->portal_source == POLICY_PORTALS_FOUND && i < d->found.count; i++)
		portal_found_tris(&d->found.portals[i], d->portals + 2 * i);
	d->n_portals = n;
	/* Marked or found, each out to the far end of the tunnel it lies in:
	 * the search's own slide stops where its sampled tests first fail, a
	 * window's frame or mullions before its far face. */
	if (n) {
		SceneView v;
		prepared_view(d, &v);
		V3 cam, fwd, up;
		float yfov;
		scene_camera(s, &cam, &fwd, &up, &yfov);
		uint32_t moved = portal_slide(&v, d->portals, n, cam);
		if (moved)
			log_msg(AJAR_LOG_INFO, "%s: %u portal triangle%s moved out through the opening%s they cover", s->source,
				moved, moved == 1 ? "" : "s", moved == 1 ? " it" : "s");
	}
	return AJAR_OK;
}

/* Bounds of the prepared triangles, instances and portals (the portals
 * in use, not those the scene marks). The flat triangles are the first
 * nflat; the instances' world bounds come from their meshes'. */
static void prepared_bounds(const Scene *s, const SceneData *d, uint32_t nflat, V3 *bmin, V3 *bmax)
{
	V3 lo = v3(AJAR_INF, AJAR_INF, AJAR_INF), hi = v3(-AJAR_INF, -AJAR_INF, -AJAR_INF);
	for (size_t i = 0; i < nflat; i++) {
		const Tri *t = &d->tris[i];
		lo = v3_min(lo, v3_min(t->p0, v3_min(t->p1, t->p2)));
		hi = v3_max(hi, v3_max(t->p0, v3_max(t->p1, t->p2)));
	}
	for (uint32_t j = 0; j < s->ninstances; j++) {
		V3 mlo, mhi, a, b;
		scene_mesh_bounds(s, s->instances[j].mesh, &mlo, &mhi);
		scene_instance_bounds(&s->instances[j], mlo, mhi, &a, &b);
		lo = v3_min(lo, a);
		hi = v3_max(hi, b);
	}
	for (size_t i = 0; i < d->n_portals; i++) {
		const PortalTri *t = &d->portals[i];
		lo = v3_min(lo, v3_min(t->p0, v3_min(t->p1, t->p2)));
		hi = v3_max(hi, v3_max(t->p0, v3_max(t->p1, t->p2)));
	}
	*bmin = lo;
	*bmax = hi;
}

ajar_status prepare_scene(Scene *s, const ajar_options *o, uint32_t width, uint32_t height,
			  const PolicyOverrides *over, SceneData *d)
{
	ajar_status st;
	uint32_t n = s->ntris;
	memset(d, 0, sizeof *d);
	if (scene_rendered_triangles(s) == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: the scene has no triangles", s->source);
	if (s->nmaterials == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: the scene has no materials", s->source);

	if ((st = scene_bvh(s, &d->share)) != AJAR_OK)
		return st;
	SceneShare *sh = d->share;
	d->nodes = sh->nodes;
	d->n_nodes = sh->nnodes;
	d->bvh_depth = sh->bvh_depth;
	d->bvh_wide_depth = sh->bvh_wide_depth;
	d->bvh_seconds = sh->bvh_seconds;
	d->tris = sh->tris;
	d->shade = sh->shade;
	d->texels = sh->texels;
	d->n_texels = sh->ntexels;
	/* Materials and textures are small: copies, so a renderer needs
	 * nothing of the scene but the share. */
	d->materials = dup_array(s->materials, s->nmaterials, sizeof *s->materials);
	d->n_materials = s->nmaterials;
	d->textures = dup_array(s->textures, s->ntextures, sizeof *s->textures);
	d->n_textures = s->ntextures;
	d->n_extra = s->extra ? n : 1; /* one unused entry, so a device buffer exists */
	d->extra = s->extra ? sh->extra : calloc(1, sizeof *d->extra);
	d->params = calloc(1, sizeof *d->params);
	if ((st = scene_bvh_instances(s, sh, &d->instances, &d->n_instances)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	if (over && over->panes_opaque) { /* a test's brute force: smooth thin glass is a delta surface */
		d->tris = dup_array(sh->tris, n, sizeof *d->tris);
		d->own_tris = 1;
		for (uint32_t i = 0; d->tris && i < n; i++)
			d->tris[i].flags &= ~TRI_PANE;
	}
	if (!d->tris || !d->params || !d->extra || !d->materials || !d->textures) {
		prepare_free(d);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory preparing %u triangles", s->source, n);
	}
	d->n_tris = d->n_shade = n;
	if ((st = choose_portals(s, o, d)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	d->kernel_omit = kernel_omit(d);

	prepared_bounds(s, d, scene_flat_triangles(s), &d->bmin, &d->bmax);
	V3 center = v3_scale(v3_add(d->bmin, d->bmax), 0.5f);
	float radius = 0.5f * v3_len(v3_sub(d->bmax, d->bmin)) * 1.001f + 1e-4f;
	/* Only flat triangles emit: they come first (scene_bvh.c), the
	 * instanced meshes after them. */
	if ((st = lights_build(s, d->tris, d->shade, d->extra, scene_flat_triangles(s), d->materials, d->portals, (uint32_t)d->n_portals, center, radius,
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
	if ((st = setup_camera(s, width, height, &p->camera)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	p->num_tris = (int)n;
	for (uint32_t i = 0; i < n; i++)
		p->num_panes += (d->tris[i].flags & TRI_PANE) != 0;
	p->num_emitters = (int)d->lights.nemitters;
	p->num_lights = (int)d->lights.nlights;
	p->light_power = d->lights.light_power;
	p->num_portals = (int)d->n_portals;
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
	/* A sky image's light subpaths start on lines through the portals
	 * (kernels/light/lights.h, line_sample); their directions follow the
	 * light that comes in through them (portal_sky_lines_build). */
	p->env_lines = 0;
	if (s->env_type == ENV_IMAGE && d->n_portals > 0) {
		if ((st = portal_sky_lines_build(p, d->portals, (uint32_t)d->n_portals, &d->lights.env,
						 &d->lights.nenv)) != AJAR_OK) {
			prepare_free(d);
			return st;
		}
		d->env = d->lights.env;
		view.env = d->env;
		d->n_env = d->lights.nenv;
		p->env_lines = 1;
		/* The planar portals whose sky tables next-event estimation
		 * samples through (kernels/light/portal_sky.h). */
		if ((st = portal_sky_planes(d->portals, (uint32_t)d->n_portals, &d->portal_planes,
					    &d->n_portal_planes)) != AJAR_OK) {
			prepare_free(d);
			return st;
		}
		d->sun_share_portals = portal_sun_share(&view, d->portals, (uint32_t)d->n_portals);
	}

	/* Every choice of strategies, rates, heuristic and tables (policy.c). */
	PolicyInput in = {
		.integrator = (int)o->integrator,
		.mis = (int)o->mis,
		.strategy_unweighted = o->strategy_unweighted,
		.portals = (uint32_t)d->n_portals,
		.env_type = s->env_type,
		.env_width = s->env_width,
		.emitters = d->lights.nemitters,
		.lamps = d->lights.nlights,
		.lamp_behind_portal = lamp_behind_portal(d, p->camera.pos),
		.sky_planes = (int)d->n_portal_planes,
		.sun_share = d->sun_share_portals,
	};
	Policy pol;
	policy_choose(&in, over, s->source, &pol);
	p->integrator = pol.integrator;
	p->mis = pol.mis;
	p->light_paths = pol.light_paths;
	p->portal_s_max = pol.portal_s_max;
	p->portal_sp_max = pol.portal_sp_max;
	p->portal_tp_max = pol.portal_tp_max;
	p->portal_t_max = pol.portal_t_max;
	p->bdpt_conn = pol.bdpt_conn;
	p->portal_rate = pol.portal_rate;
	d->sky_res = pol.sky_res;
	p->emitter_power = d->lights.emitter_power;
	p->env_power = d->lights.env_power;
	if ((st = portal_sky_tables(&view, d->portal_planes, d->n_portal_planes, d->sky_res, &d->portal_sky,
				    &d->n_portal_sky)) != AJAR_OK) {
		prepare_free(d);
		return st;
	}
	p->num_portal_planes = (int)d->n_portal_planes;
	if (p->num_panes && p->env_type != ENV_NONE)
		pane_planes_build(d->tris, scene_flat_triangles(s), d->portals, (uint32_t)d->n_portals, radius, p);
	if (p->num_emitters == 0 && p->num_lights == 0 && p->env_type == ENV_NONE)
		log_msg(AJAR_LOG_WARNING, "%s: no emissive triangles, no lights and no environment: the image is black",
			s->source);
	return AJAR_OK;
}

void prepare_free(SceneData *d)
{
	/* nodes, shade, texels, tris and extra (unless copies) are the share's. */
	if (d->own_tris)
		free(d->tris);
	if (!d->share || d->extra != d->share->extra)
		free(d->extra);
	free(d->materials);
	free(d->textures);
	free(d->params);
	free(d->portals);
	free(d->portal_planes);
	free(d->portal_sky);
	free(d->instances);
	lights_free(&d->lights);
	portal_search_free(&d->found);
	scene_share_release(d->share);
	memset(d, 0, sizeof *d);
}
