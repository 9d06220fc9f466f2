/* scene_api.c — the scene half of the public API (include/ajar.h): loading,
 * building a scene in code, and the summary in ajar_scene_info.
 *
 * The public ajar_scene is the internal Scene (scene.h). This file checks
 * the caller's arguments (AJAR_ERROR_INVALID_ARGUMENT), converts public
 * structs to device ones and applies mesh transforms; scene.c does the
 * geometry checks every source of triangles shares. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/error.h"
#include "scene/gltf.h"
#include "scene/scene.h"
#include "scene/scene_share.h"

ajar_status ajar_scene_load(const char *path, ajar_scene **out)
{
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_load: out is NULL");
	*out = NULL;
	if (!path || !*path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_load: no path");
	return ajar_scene_load_with(path, NULL, out);
}

void ajar_load_options_default(ajar_load_options *o)
{
	if (o)
		memset(o, 0, sizeof *o);
}

ajar_status ajar_scene_load_with(const char *path, const ajar_load_options *o, ajar_scene **out)
{
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_load_with: out is NULL");
	*out = NULL;
	if (!path || !*path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_load_with: no path");
	struct timespec t0, t1;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	ajar_status st = gltf_load_instancing(path, o ? o->allow_outside_files : 0, GLTF_INSTANCING_AUTO, out);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	if (st == AJAR_OK)
		(*out)->load_seconds = (double)(t1.tv_sec - t0.tv_sec) + (t1.tv_nsec - t0.tv_nsec) * 1e-9;
	return st;
}

ajar_status ajar_scene_create(ajar_scene **out)
{
	if (!out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_create: out is NULL");
	return scene_new("<api>", out);
}

void ajar_scene_destroy(ajar_scene **scene)
{
	if (!scene)
		return;
	scene_free(*scene);
	*scene = NULL;
}

void ajar_material_default(ajar_material *m)
{
	memset(m, 0, sizeof *m);
	m->base_color[0] = m->base_color[1] = m->base_color[2] = 0.8f;
	m->metallic = 0.0f;
	m->roughness = 1.0f;
	m->specular = 0.0f;
	m->transmission = 0.0f;
	m->ior = 1.5f;
	m->double_sided = 1;
	m->attenuation_color[0] = m->attenuation_color[1] = m->attenuation_color[2] = 1.0f;
}

/* NaN fails every comparison, so `!(lo <= v && v <= hi)` rejects it too. */
static int in_range(float v, float lo, float hi) { return lo <= v && v <= hi; }

ajar_status ajar_scene_add_material(ajar_scene *s, const ajar_material *m, uint32_t *id)
{
	if (!s || !m)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_add_material: NULL scene or material");
	const char *bad = NULL;
	for (int i = 0; i < 3; i++) {
		if (!in_range(m->base_color[i], 0.0f, 1.0f))
			bad = "base_color must be in [0, 1]";
		if (!in_range(m->emission[i], 0.0f, AJAR_INF))
			bad = "emission must be finite and >= 0";
	}
	if (!in_range(m->metallic, 0.0f, 1.0f))
		bad = "metallic must be in [0, 1]";
	else if (!in_range(m->roughness, 0.0f, 1.0f))
		bad = "roughness must be in [0, 1]";
	else if (!in_range(m->specular, 0.0f, 1.0f))
		bad = "specular must be in [0, 1]";
	else if (!in_range(m->transmission, 0.0f, 1.0f))
		bad = "transmission must be in [0, 1]";
	else if (!in_range(m->ior, 1.0f, 10.0f))
		bad = "ior must be in [1, 10]";
	else if (!in_range(m->thickness, 0.0f, AJAR_INF))
		bad = "thickness must be finite and >= 0";
	else if (!in_range(m->attenuation_distance, 0.0f, AJAR_INF))
		bad = "attenuation_distance must be finite and >= 0";
	for (int i = 0; i < 3 && !bad; i++)
		if (!in_range(m->attenuation_color[i], 0.0f, 1.0f))
			bad = "attenuation_color must be in [0, 1]";
	if (bad)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: material %u: %s", s->source, s->nmaterials, bad);

	Material d;
	memset(&d, 0, sizeof d);
	d.base_color = v3(m->base_color[0], m->base_color[1], m->base_color[2]);
	d.base_tex = -1;
	d.emission = v3(m->emission[0], m->emission[1], m->emission[2]);
	d.metallic = m->metallic;
	d.roughness = m->roughness;
	d.transmission = m->transmission;
	d.ior = m->ior;
	d.specular = m->specular;
	d.flags = m->double_sided ? MATERIAL_DOUBLE_SIDED : 0;
	d.alpha_cutoff = 0.5f;
	if (m->thickness > 0.0f) {
		d.flags |= MATERIAL_VOLUME;
		float sg[3];
		for (int i = 0; i < 3; i++)
			sg[i] = m->attenuation_distance > 0.0f
					? fminf(-logf(fmaxf(m->attenuation_color[i], 1e-30f)) / m->attenuation_distance, 1e30f)
					: 0.0f;
		d.sigma = v3(sg[0], sg[1], sg[2]);
	}
	return scene_add_material(s, &d, id);
}

/* A mesh's vertices in world space: positions (and normals) transformed,
 * indices made explicit and reversed where the transform mirrors, so that
 * front faces stay counter-clockwise. */
typedef struct {
	float *pos, *nrm;
	uint32_t *idx;
} WorldMesh;

static void world_mesh_free(WorldMesh *w)
{
	free(w->pos);
	free(w->nrm);
	free(w->idx);
}

static ajar_status world_mesh(const Scene *s, const char *what, const ajar_mesh *m, WorldMesh *w)
{
	memset(w, 0, sizeof *w);
	if (!m->positions)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: positions is NULL", s->source, what);
	if (m->triangle_count == 0)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: triangle_count is 0", s->source, what);
	if (!m->indices && (uint64_t)m->triangle_count * 3 > m->vertex_count)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: %u triangles need %llu vertices, have %u",
			       s->source, what, m->triangle_count, (unsigned long long)m->triangle_count * 3,
			       m->vertex_count);
	if (!m->transform)
		return AJAR_OK;

	const float *t = m->transform; /* column-major: element (r, c) is t[4c + r] */
	for (int i = 0; i < 16; i++)
		if (!isfinite(t[i]))
			return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: transform is not finite", s->source, what);
	if (t[3] != 0.0f || t[7] != 0.0f || t[11] != 0.0f || t[15] != 1.0f)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: transform is not affine (last row must be 0 0 0 1)",
			       s->source, what);
	double a[3][3];
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++)
			a[r][c] = t[4 * c + r];
	/* Cofactors: (A^-1)^T = cof(A) / det(A), the normal matrix. */
	double cof[3][3];
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) {
			int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
			cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
		}
	double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
	if (!(fabs(det) > 0.0))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: transform is singular", s->source, what);

	size_t nv = m->vertex_count;
	w->pos = malloc(nv * 3 * sizeof *w->pos + 1);
	w->nrm = m->normals ? malloc(nv * 3 * sizeof *w->nrm + 1) : NULL;
	w->idx = det < 0.0 ? malloc((size_t)m->triangle_count * 3 * sizeof *w->idx) : NULL;
	if (!w->pos || (m->normals && !w->nrm) || (det < 0.0 && !w->idx)) {
		world_mesh_free(w);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: %s: out of memory", s->source, what);
	}
	for (size_t v = 0; v < nv; v++) {
		const float *p = m->positions + 3 * v;
		for (int r = 0; r < 3; r++) {
			w->pos[3 * v + r] = (float)(a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2] + t[12 + r]);
			if (w->nrm) {
				const float *n = m->normals + 3 * v;
				w->nrm[3 * v + r] = (float)((cof[r][0] * n[0] + cof[r][1] * n[1] + cof[r][2] * n[2]) / det);
			}
		}
	}
	if (w->idx)
		for (size_t i = 0; i < m->triangle_count; i++) {
			uint32_t k0 = m->indices ? m->indices[3 * i] : (uint32_t)(3 * i);
			uint32_t k1 = m->indices ? m->indices[3 * i + 1] : (uint32_t)(3 * i + 1);
			uint32_t k2 = m->indices ? m->indices[3 * i + 2] : (uint32_t)(3 * i + 2);
			w->idx[3 * i] = k0;
			w->idx[3 * i + 1] = k2;
			w->idx[3 * i + 2] = k1;
		}
	return AJAR_OK;
}

ajar_status ajar_scene_add_mesh(ajar_scene *s, const ajar_mesh *mesh)
{
	if (!s || !mesh)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_add_mesh: NULL scene or mesh");
	if (mesh->material >= s->nmaterials)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: ajar_scene_add_mesh: material %u does not exist (%u materials)",
			       s->source, mesh->material, s->nmaterials);
	WorldMesh w;
	ajar_status st = world_mesh(s, "ajar_scene_add_mesh", mesh, &w);
	if (st)
		return st;
	st = scene_add_triangles(s, "ajar_scene_add_mesh", w.pos ? w.pos : mesh->positions,
				 w.pos ? w.nrm : mesh->normals, mesh->uvs, mesh->vertex_count,
				 w.idx ? w.idx : mesh->indices, mesh->triangle_count, mesh->material);
	world_mesh_free(&w);
	/* Bad geometry from a caller is the caller's mistake, not a bad file. */
	return st == AJAR_ERROR_BAD_INPUT ? AJAR_ERROR_INVALID_ARGUMENT : st;
}

ajar_status ajar_scene_add_portal(ajar_scene *s, const ajar_mesh *mesh)
{
	if (!s || !mesh)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_add_portal: NULL scene or mesh");
	WorldMesh w;
	ajar_status st = world_mesh(s, "ajar_scene_add_portal", mesh, &w);
	if (st)
		return st;
	st = scene_add_portal(s, "ajar_scene_add_portal", w.pos ? w.pos : mesh->positions, mesh->vertex_count,
			      w.idx ? w.idx : mesh->indices, mesh->triangle_count);
	world_mesh_free(&w);
	return st == AJAR_ERROR_BAD_INPUT ? AJAR_ERROR_INVALID_ARGUMENT : st;
}

void ajar_light_default(ajar_light *l)
{
	if (!l)
		return;
	memset(l, 0, sizeof *l);
	l->type = AJAR_LIGHT_POINT;
	l->direction[2] = -1.0f;
	l->color[0] = l->color[1] = l->color[2] = 1.0f;
	l->intensity = 1.0f;
	l->outer_cone = 0.25f * AJAR_PI;
}

ajar_status ajar_scene_add_light(ajar_scene *s, const ajar_light *l)
{
	if (!s || !l)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_add_light: NULL scene or light");
	char what[48];
	snprintf(what, sizeof what, "ajar_scene_add_light (light %u)", s->nlights);
	ajar_status st = scene_add_light(s, what, l);
	return st == AJAR_ERROR_BAD_INPUT ? AJAR_ERROR_INVALID_ARGUMENT : st;
}

ajar_status ajar_scene_light_get(const ajar_scene *s, uint32_t index, ajar_light *out)
{
	if (!s || !out)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_light_get: NULL argument");
	if (index >= s->nlights)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_light_get: light %u does not exist (%u lights)",
			       index, s->nlights);
	*out = s->lights[index];
	return AJAR_OK;
}

ajar_status ajar_scene_set_camera(ajar_scene *s, const ajar_camera *c)
{
	if (!s || !c)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_set_camera: NULL scene or camera");
	V3 pos = v3(c->position[0], c->position[1], c->position[2]);
	V3 target = v3(c->target[0], c->target[1], c->target[2]);
	V3 up = v3(c->up[0], c->up[1], c->up[2]);
	return scene_set_camera(s, pos, v3_sub(target, pos), up, c->yfov, c->aspect);
}

ajar_status ajar_scene_set_environment_color(ajar_scene *s, const float rgb[3])
{
	if (!s || !rgb)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_set_environment_color: NULL argument");
	for (int i = 0; i < 3; i++)
		if (!in_range(rgb[i], 0.0f, AJAR_INF))
			return err_set(AJAR_ERROR_INVALID_ARGUMENT,
				       "%s: environment colour (%g, %g, %g) must be finite and >= 0", s->source, rgb[0],
				       rgb[1], rgb[2]);
	scene_set_env_color(s, v3(rgb[0], rgb[1], rgb[2]));
	return AJAR_OK;
}

ajar_status ajar_scene_set_environment_image(ajar_scene *s, const char *exr_path, float strength)
{
	if (!s || !exr_path)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_set_environment_image: NULL argument");
	if (!in_range(strength, 0.0f, AJAR_INF))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: environment strength %g must be finite and >= 0",
			       s->source, strength);
	return scene_load_env_image(s, exr_path, strength);
}

ajar_status ajar_scene_set_environment_rotation(ajar_scene *s, float degrees)
{
	if (!s)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_set_environment_rotation: NULL scene");
	return scene_set_env_rotation(s, degrees);
}

static int texture_of(const Material *m, int which)
{
	return which == 0 ? m->base_tex : which == 1 ? m->mr_tex - 1 : which == 2 ? m->emissive_tex - 1 : m->normal_tex - 1;
}

/* Distinct images behind the textures of one kind: which = 0 base colour,
 * 1 metallic-roughness, 2 emissive, 3 normal. */
static uint32_t count_images(const ajar_scene *s, int which)
{
	uint32_t n = 0;
	for (uint32_t i = 0; i < s->nmaterials; i++) {
		int t = texture_of(&s->materials[i], which), seen = t < 0;
		for (uint32_t j = 0; j < i && !seen; j++) {
			int u = texture_of(&s->materials[j], which);
			seen = u >= 0 && s->textures[u].offset == s->textures[t].offset;
		}
		n += !seen;
	}
	return n;
}

ajar_status ajar_scene_info_get(const ajar_scene *s, ajar_scene_info *info)
{
	if (!s || !info)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_scene_info_get: NULL argument");
	memset(info, 0, sizeof *info);
	info->triangles = scene_rendered_triangles(s);
	info->materials = s->nmaterials;
	info->emissive_triangles = scene_count_emissive(s);
	info->portal_triangles = s->nportal_tris;
	info->portals = s->nportals;
	info->textures = s->nimages;
	info->base_color_textures = count_images(s, 0);
	info->metallic_roughness_textures = count_images(s, 1);
	info->emissive_textures = count_images(s, 2);
	info->normal_textures = count_images(s, 3);
	info->texture_bytes = (uint64_t)s->ntexels * sizeof *s->texels;
	/* Every copy an instance draws counts. */
	for (uint32_t i = 0, k = 0; i < s->ntris; i++) {
		while (k < s->nmeshes && i >= s->meshes[k].first + s->meshes[k].count)
			k++;
		int in_mesh = k < s->nmeshes && i >= s->meshes[k].first;
		if (!(s->tris[i].flags & TRI_ALPHA))
			continue;
		if (!in_mesh) {
			info->alpha_triangles++;
			continue;
		}
		for (uint32_t j = 0; j < s->ninstances; j++)
			info->alpha_triangles += s->instances[j].mesh == k;
	}
	info->environment = s->env_type == ENV_IMAGE ? 2 : s->env_type == ENV_COLOR ? 1 : 0;
	V3 lo, hi;
	scene_bounds(s, &lo, &hi);
	info->bounds_min[0] = lo.x;
	info->bounds_min[1] = lo.y;
	info->bounds_min[2] = lo.z;
	info->bounds_max[0] = hi.x;
	info->bounds_max[1] = hi.y;
	info->bounds_max[2] = hi.z;
	V3 pos, fwd, up;
	float yfov;
	scene_camera(s, &pos, &fwd, &up, &yfov);
	ajar_camera *c = &info->camera;
	c->position[0] = pos.x;
	c->position[1] = pos.y;
	c->position[2] = pos.z;
	c->target[0] = pos.x + fwd.x;
	c->target[1] = pos.y + fwd.y;
	c->target[2] = pos.z + fwd.z;
	c->up[0] = up.x;
	c->up[1] = up.y;
	c->up[2] = up.z;
	c->yfov = yfov;
	c->aspect = s->has_camera ? s->cam_aspect : 0.0f;
	info->has_camera = s->has_camera;
	info->width = s->width;
	info->height = s->height;
	info->lights = s->nlights;
	info->unique_triangles = s->ntris;
	info->instances = s->ninstances;
	info->geometry_bytes = (uint64_t)s->ntris * (sizeof *s->tris + sizeof *s->shade + (s->extra ? sizeof *s->extra : 0));
	if (s->share && s->share->nodes) {
		info->bvh_bytes = (uint64_t)s->share->nnodes * sizeof(BvhNode);
		info->bvh_seconds = s->share->bvh_seconds;
	}
	info->load_seconds = s->load_seconds;
	return AJAR_OK;
}
