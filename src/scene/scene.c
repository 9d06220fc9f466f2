/* scene.c — the host scene: growable arrays of the shared device types,
 * filled by the glTF loader and the public builder API.
 *
 * Everything that enters a Scene passes through the functions here, which
 * check it once (finite numbers, indices in range, materials that exist) so
 * that the BVH, the light tables and the kernels can trust the arrays.
 * Messages name s->source (the file, or "<api>") and the caller's `what`. */
#include "scene/scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/big_array.h"
#include "core/error.h"
#include "image/exr.h"
#include "image/hdr.h"
#include "material/bsdf.h"
#include "material/texture.h"
#include "scene/emit_mask.h"
#include "scene/scene_share.h"

/* Device code indexes with int, so no array may pass INT32_MAX entries. */
#define SCENE_MAX_ITEMS ((size_t)INT32_MAX)

/* Makes room for `need` items of `size` bytes in *arr (capacity *cap),
 * doubling so that n appends cost O(n). */
static ajar_status grow(void **arr, size_t *cap, size_t need, size_t size)
{
	if (need <= *cap)
		return AJAR_OK;
	size_t ncap = *cap ? *cap : 16;
	while (ncap < need)
		ncap *= 2;
	if (ncap > SIZE_MAX / size)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: array of %zu items is too large", need);
	void *p = realloc(*arr, ncap * size);
	if (!p)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: out of memory for %zu items", need);
	*arr = p;
	*cap = ncap;
	return AJAR_OK;
}

/* grow() for the big arrays (core/big_array.h): page-aligned, grown in
 * place, written only where filled. */
static ajar_status grow_big(void **arr, size_t *cap, size_t need, size_t size)
{
	if (need <= *cap)
		return AJAR_OK;
	size_t ncap = *cap ? *cap : 16;
	while (ncap < need)
		ncap *= 2;
	if (ncap > SIZE_MAX / size)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: array of %zu items is too large", need);
	void *p = big_resize(*arr, *cap * size, ncap * size);
	if (!p)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: out of memory for %zu items", need);
	*arr = p;
	*cap = ncap;
	return AJAR_OK;
}

/* grow() for the uint32_t capacities of the Scene struct. */
static ajar_status grow32(void **arr, uint32_t *cap, size_t need, size_t size)
{
	size_t c = *cap;
	ajar_status st = grow(arr, &c, need, size);
	*cap = c > UINT32_MAX ? UINT32_MAX : (uint32_t)c;
	return st;
}

ajar_status scene_new(const char *source, Scene **out)
{
	*out = NULL;
	Scene *s = calloc(1, sizeof *s);
	if (!s)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: out of memory");
	s->source = strdup(source ? source : "<api>");
	if (!s->source) {
		free(s);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "scene: out of memory");
	}
	s->env_type = ENV_NONE;
	s->env_strength = 1.0f;
	*out = s;
	return AJAR_OK;
}

void scene_free(Scene *s)
{
	if (!s)
		return;
	free(s->source);
	if (s->share) {
		scene_share_release(s->share); /* the arrays go with the last holder */
	} else {
		big_free(s->tris, (size_t)s->cap_tris * sizeof *s->tris);
		big_free(s->shade, (size_t)s->cap_tris * sizeof *s->shade);
		big_free(s->texels, s->cap_texels * sizeof *s->texels);
		big_free(s->extra, s->cap_extra * sizeof *s->extra);
	}
	free(s->materials);
	free(s->textures);
	free(s->portals);
	free(s->env_rgb);
	free(s->lights);
	free(s->meshes);
	free(s->instances);
	free(s);
}

ajar_status scene_add_material(Scene *s, const Material *m, uint32_t *id)
{
	if (s->nmaterials >= SCENE_MAX_ITEMS)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: too many materials", s->source);
	if (m->base_tex >= (int)s->ntextures || m->base_tex < -1)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: material %u: texture %d does not exist (%u textures)",
			       s->source, s->nmaterials, m->base_tex, s->ntextures);
	const int tex[] = {m->mr_tex,	       m->emissive_tex,	      m->normal_tex,	      m->transmission_tex,
			   m->specular_tex,    m->specular_color_tex, m->sheen_color_tex,     m->sheen_rough_tex,
			   m->clearcoat_tex,   m->clearcoat_rough_tex, m->clearcoat_normal_tex, m->anisotropy_tex};
	for (size_t k = 0; k < sizeof tex / sizeof tex[0]; k++)
		if (tex[k] < 0 || tex[k] > (int)s->ntextures)
			return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: material %u: texture %d does not exist (%u textures)",
				       s->source, s->nmaterials, tex[k] - 1, s->ntextures);
	ajar_status st = grow32((void **)&s->materials, &s->cap_materials, (size_t)s->nmaterials + 1,
				sizeof *s->materials);
	if (st)
		return st;
	s->materials[s->nmaterials] = *m;
	if (id)
		*id = s->nmaterials;
	s->nmaterials++;
	return AJAR_OK;
}

ajar_status scene_add_texture(Scene *s, uint32_t width, uint32_t height, const uint8_t *rgba, uint32_t *id)
{
	if (width == 0 || height == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: texture %u: empty image (%ux%u)", s->source,
			       s->ntextures, width, height);
	size_t n = (size_t)width * height;
	if (n > SCENE_MAX_ITEMS - s->ntexels || s->ntextures >= SCENE_MAX_ITEMS)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: texture %u: %ux%u texels exceed the texel budget",
			       s->source, s->ntextures, width, height);
	ajar_status st = grow32((void **)&s->textures, &s->cap_textures, (size_t)s->ntextures + 1,
				sizeof *s->textures);
	if (!st)
		st = scene_private(s);
	if (!st)
		st = grow_big((void **)&s->texels, &s->cap_texels, s->ntexels + n, sizeof *s->texels);
	if (st)
		return st;
	uint32_t *dst = s->texels + s->ntexels;
	for (size_t i = 0; i < n; i++) {
		const uint8_t *p = rgba + 4 * i;
		dst[i] = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
	}
	Texture *t = &s->textures[s->ntextures];
	memset(t, 0, sizeof *t);
	t->offset = (int)s->ntexels;
	t->width = (int)width;
	t->height = (int)height;
	t->xf[0] = t->xf[4] = 1.0f;
	s->ntexels += n;
	s->nimages++;
	if (id)
		*id = s->ntextures;
	s->ntextures++;
	return AJAR_OK;
}

ajar_status scene_add_texture_use(Scene *s, uint32_t image, int flags, const float xf[6], uint32_t *id)
{
	if (image >= s->ntextures)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: texture %u does not exist (%u textures)", s->source,
			       image, s->ntextures);
	for (int i = 0; i < 6; i++)
		if (!isfinite(xf[i]))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: texture %u: transform is not finite", s->source,
				       s->ntextures);
	if (s->ntextures >= SCENE_MAX_ITEMS)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: too many textures", s->source);
	ajar_status st = grow32((void **)&s->textures, &s->cap_textures, (size_t)s->ntextures + 1,
				sizeof *s->textures);
	if (st)
		return st;
	Texture *t = &s->textures[s->ntextures];
	*t = s->textures[image];
	t->flags = flags;
	memcpy(t->xf, xf, sizeof t->xf);
	if (id)
		*id = s->ntextures;
	s->ntextures++;
	return AJAR_OK;
}

/* Coordinates and directions are finite and at most SCENE_MAX_COORD in
 * size, so their squares (lengths, areas, the BVH's centroid sums) stay
 * finite in float: a vertex at 3e38, finite, gave NaN bins in the BVH
 * (fuzz_gltf, UBSan: NaN cast to int). */
#define SCENE_MAX_COORD 1e18f

static int all_finite(const float *v, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (!(fabsf(v[i]) <= SCENE_MAX_COORD))
			return 0;
	return 1;
}

/* Checks what scene_add_triangles and scene_add_portal share: finite
 * positions and indices in range. idx NULL means vertices taken in threes. */
static ajar_status check_geometry(const Scene *s, const char *what, const float *pos, uint32_t nverts,
				  const uint32_t *idx, uint32_t ntris, uint32_t have)
{
	if (!pos)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: no positions", s->source, what);
	if ((size_t)ntris > SCENE_MAX_ITEMS - have)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: %u more triangles exceed the limit of %zu",
			       s->source, what, ntris, SCENE_MAX_ITEMS);
	for (uint32_t v = 0; v < nverts; v++)
		if (!all_finite(pos + 3 * (size_t)v, 3))
			return err_set(AJAR_ERROR_BAD_INPUT,
				       "%s: %s: vertex %u: position (%g, %g, %g) is not finite or beyond 1e18",
				       s->source, what, v, pos[3 * (size_t)v], pos[3 * (size_t)v + 1],
				       pos[3 * (size_t)v + 2]);
	if (!idx) {
		if ((uint64_t)ntris * 3 > nverts)
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: %u triangles need %llu vertices, have %u",
				       s->source, what, ntris, (unsigned long long)ntris * 3, nverts);
		return AJAR_OK;
	}
	for (size_t i = 0; i < (size_t)ntris * 3; i++)
		if (idx[i] >= nverts)
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: index %u (triangle %zu) out of range (%u vertices)",
				       s->source, what, idx[i], i / 3, nverts);
	return AJAR_OK;
}

static V3 load3(const float *a, uint32_t i) { return v3(a[3 * (size_t)i], a[3 * (size_t)i + 1], a[3 * (size_t)i + 2]); }

ajar_status scene_add_triangles(Scene *s, const char *what, const float *pos, const float *normals,
				const float *uvs, uint32_t nverts, const uint32_t *idx, uint32_t ntris,
				uint32_t material)
{
	return scene_add_triangles_ex(s, what, pos, normals, uvs, NULL, NULL, NULL, nverts, idx, ntris, material);
}

static void extra_default(TriExtra *e)
{
	memset(e, 0, sizeof *e);
	for (int c = 0; c < 4; c++)
		e->c0[c] = e->c1[c] = e->c2[c] = 1.0f;
}

/* TriExtra entries for triangles [s->ntris, s->ntris + ntris), made when
 * the first triangle with extra attributes arrives (earlier ones get the
 * defaults: coordinates 0, colour 1). */
static ajar_status extra_reserve(Scene *s, const char *what, uint32_t ntris)
{
	size_t have = s->extra ? s->ntris : 0, need = (size_t)s->ntris + ntris;
	ajar_status st = grow_big((void **)&s->extra, &s->cap_extra, need, sizeof *s->extra);
	if (st)
		return err_set(st, "%s: %s: out of memory for vertex attributes", s->source, what);
	for (size_t i = have; i < need; i++)
		extra_default(&s->extra[i]);
	return AJAR_OK;
}

ajar_status scene_add_triangles_ex(Scene *s, const char *what, const float *pos, const float *normals,
				   const float *uvs, const float *uvs1, const float *colors, const float *tangents,
				   uint32_t nverts,
				   const uint32_t *idx, uint32_t ntris, uint32_t material)
{
	ajar_status st = check_geometry(s, what, pos, nverts, idx, ntris, s->ntris);
	if (st)
		return st;
	if (uvs1 && !all_finite(uvs1, 2 * (size_t)nverts))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: TEXCOORD_1 is not finite", s->source, what);
	if (colors)
		for (size_t i = 0; i < 4 * (size_t)nverts; i++)
			if (!(colors[i] >= 0.0f && colors[i] <= 1.0f))
				return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: vertex %zu: colour is not in [0, 1]",
					       s->source, what, i / 4);
	if (tangents && !all_finite(tangents, 4 * (size_t)nverts))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: a tangent is not finite", s->source, what);
	if (material < s->nmaterials && !s->materials[material].normal_tex && !s->materials[material].clearcoat_normal_tex &&
	    !(s->materials[material].anisotropy > 0.0f))
		tangents = NULL; /* only normal maps and anisotropy read them */
	if ((st = scene_private(s)) != AJAR_OK)
		return st;
	if ((uvs1 || colors || tangents || s->extra) && (st = extra_reserve(s, what, ntris)))
		return st;
	if (material >= s->nmaterials)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: material %u does not exist (%u materials)", s->source,
			       what, material, s->nmaterials);
	/* Rays test the alpha only of triangles that can be transparent. */
	const Material *mat = &s->materials[material];
	int alpha = (mat->flags & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) &&
		    (mat->base_tex >= 0 || colors ||
		     !(mat->base_alpha >= (mat->flags & MATERIAL_ALPHA_MASK ? mat->alpha_cutoff : 1.0f)));
	/* Panes: thin-walled glass that may be smooth (its roughness factor
	 * below the delta limit, or a roughness texture): shadow rays and
	 * connections cross them (kernels/geom/visibility.h). Emissive glass
	 * stays a surface that emits where it is hit. */
	int pane = !(mat->flags & MATERIAL_VOLUME) && mat->transmission > 0.0f && (mat->metallic < 1.0f || mat->mr_tex) &&
		   (mat->roughness * mat->roughness < BSDF_DELTA_ALPHA || mat->mr_tex) && v3_is_zero(mat->emission);
	if (normals)
		for (uint32_t v = 0; v < nverts; v++)
			if (!all_finite(normals + 3 * (size_t)v, 3))
				return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: vertex %u: normal is not finite",
					       s->source, what, v);
	if (uvs)
		for (uint32_t v = 0; v < nverts; v++)
			if (!all_finite(uvs + 2 * (size_t)v, 2))
				return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: vertex %u: texture coordinate is not finite",
					       s->source, what, v);

	/* tris and shade share cap_tris, which only grows once both have. */
	size_t need = (size_t)s->ntris + ntris;
	if (need > s->cap_tris) {
		size_t ncap = s->cap_tris ? s->cap_tris : 16;
		while (ncap < need)
			ncap *= 2;
		if (ncap > UINT32_MAX)
			ncap = UINT32_MAX;
		Tri *t = big_resize(s->tris, (size_t)s->cap_tris * sizeof *t, ncap * sizeof *t);
		if (!t)
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: %s: out of memory", s->source, what);
		s->tris = t;
		TriShade *sh = big_resize(s->shade, (size_t)s->cap_tris * sizeof *sh, ncap * sizeof *sh);
		if (!sh) {
			/* tris grew alone: shrink it back so both keep cap_tris */
			Tri *back = big_resize(s->tris, ncap * sizeof *t, (size_t)s->cap_tris * sizeof *t);
			if (back)
				s->tris = back;
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: %s: out of memory", s->source, what);
		}
		s->shade = sh;
		s->cap_tris = (uint32_t)ncap;
	}

	for (uint32_t t = 0; t < ntris; t++) {
		uint32_t k[3];
		for (int j = 0; j < 3; j++)
			k[j] = idx ? idx[3 * (size_t)t + j] : 3 * t + (uint32_t)j;
		Tri *tri = &s->tris[s->ntris + t];
		TriShade *sh = &s->shade[s->ntris + t];
		memset(tri, 0, sizeof *tri);
		memset(sh, 0, sizeof *sh);
		tri->p0 = load3(pos, k[0]);
		tri->p1 = load3(pos, k[1]);
		tri->p2 = load3(pos, k[2]);
		tri->material = (int)material;
		tri->emitter = -1;
		if (alpha)
			tri->flags |= TRI_ALPHA;
		if (pane)
			tri->flags |= TRI_PANE;
		if (normals) {
			V3 n[3];
			sh->has_normals = 1;
			for (int j = 0; j < 3; j++) {
				n[j] = load3(normals, k[j]);
				float len = v3_len(n[j]);
				/* A zero (or underflowing) normal has no direction: the
				 * geometric normal is the honest fallback. */
				if (!(len > 1e-20f) || !isfinite(1.0f / len))
					sh->has_normals = 0;
				else
					n[j] = v3_scale(n[j], 1.0f / len);
			}
			if (sh->has_normals) {
				sh->n0 = n[0];
				sh->n1 = n[1];
				sh->n2 = n[2];
			}
		}
		if (uvs1 || colors || tangents) {
			TriExtra *e = &s->extra[s->ntris + t];
			tri->flags |= TRI_EXTRA;
			if (tangents) {
				tri->flags |= TRI_TANGENT;
				for (int c = 0; c < 4; c++) {
					e->t0[c] = tangents[4 * (size_t)k[0] + c];
					e->t1[c] = tangents[4 * (size_t)k[1] + c];
					e->t2[c] = tangents[4 * (size_t)k[2] + c];
				}
			}
			if (uvs1) {
				e->u0 = uvs1[2 * (size_t)k[0]];
				e->v0 = uvs1[2 * (size_t)k[0] + 1];
				e->u1 = uvs1[2 * (size_t)k[1]];
				e->v1 = uvs1[2 * (size_t)k[1] + 1];
				e->u2 = uvs1[2 * (size_t)k[2]];
				e->v2 = uvs1[2 * (size_t)k[2] + 1];
			}
			if (colors)
				for (int c = 0; c < 4; c++) {
					e->c0[c] = colors[4 * (size_t)k[0] + c];
					e->c1[c] = colors[4 * (size_t)k[1] + c];
					e->c2[c] = colors[4 * (size_t)k[2] + c];
				}
		}
		if (uvs) {
			sh->u0 = uvs[2 * (size_t)k[0]];
			sh->v0 = uvs[2 * (size_t)k[0] + 1];
			sh->u1 = uvs[2 * (size_t)k[1]];
			sh->v1 = uvs[2 * (size_t)k[1] + 1];
			sh->u2 = uvs[2 * (size_t)k[2]];
			sh->v2 = uvs[2 * (size_t)k[2] + 1];
		}
	}
	s->ntris += ntris;
	return AJAR_OK;
}

ajar_status scene_add_mesh_range(Scene *s, const char *what, uint32_t first, uint32_t *id)
{
	uint32_t end = s->nmeshes ? s->meshes[s->nmeshes - 1].first + s->meshes[s->nmeshes - 1].count : 0;
	if (first < end || first >= s->ntris)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: triangles from %u overlap a mesh or do not exist",
			       s->source, what, first);
	ajar_status st = scene_private(s);
	if (!st)
		st = grow32((void **)&s->meshes, &s->cap_meshes, (size_t)s->nmeshes + 1, sizeof *s->meshes);
	if (st)
		return st;
	s->meshes[s->nmeshes].first = first;
	s->meshes[s->nmeshes].count = s->ntris - first;
	*id = s->nmeshes++;
	return AJAR_OK;
}

ajar_status scene_add_instance(Scene *s, const char *what, uint32_t mesh, const double m[16])
{
	if (mesh >= s->nmeshes)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: %s: mesh %u does not exist (%u meshes)", s->source, what,
			       mesh, s->nmeshes);
	for (int k = 0; k < 16; k++)
		if (!isfinite(m[k]))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: transform is not finite", s->source, what);
	double det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
		     m[8] * (m[1] * m[6] - m[5] * m[2]);
	if (!(fabs(det) > 0.0) || !isfinite(det))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: transform is singular", s->source, what);
	ajar_status st = scene_private(s);
	if (!st)
		st = grow32((void **)&s->instances, &s->cap_instances, (size_t)s->ninstances + 1, sizeof *s->instances);
	if (st)
		return st;
	SceneInstance *in = &s->instances[s->ninstances++];
	in->mesh = mesh;
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 4; c++)
			in->m[4 * r + c] = m[4 * c + r];
	return AJAR_OK;
}

uint32_t scene_flat_triangles(const Scene *s)
{
	uint32_t n = s->ntris;
	for (uint32_t k = 0; k < s->nmeshes; k++)
		n -= s->meshes[k].count;
	return n;
}

uint64_t scene_rendered_triangles(const Scene *s)
{
	uint64_t n = scene_flat_triangles(s);
	for (uint32_t i = 0; i < s->ninstances; i++)
		n += s->meshes[s->instances[i].mesh].count;
	return n;
}

ajar_status scene_add_portal(Scene *s, const char *what, const float *pos, uint32_t nverts, const uint32_t *idx,
			     uint32_t ntris)
{
	ajar_status st = check_geometry(s, what, pos, nverts, idx, ntris, s->nportal_tris);
	if (st)
		return st;
	if (ntris == 0)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: portal has no triangles", s->source, what);
	st = grow32((void **)&s->portals, &s->cap_portals, (size_t)s->nportal_tris + ntris, sizeof *s->portals);
	if (st)
		return st;
	for (uint32_t t = 0; t < ntris; t++) {
		uint32_t k[3];
		for (int j = 0; j < 3; j++)
			k[j] = idx ? idx[3 * (size_t)t + j] : 3 * t + (uint32_t)j;
		PortalTri *p = &s->portals[s->nportal_tris + t];
		memset(p, 0, sizeof *p);
		p->p0 = load3(pos, k[0]);
		p->p1 = load3(pos, k[1]);
		p->p2 = load3(pos, k[2]);
		V3 c = v3_cross(v3_sub(p->p1, p->p0), v3_sub(p->p2, p->p0));
		p->area = 0.5f * v3_len(c);
		p->n = p->area > 0.0f ? v3_norm(c) : v3(0.0f, 0.0f, 1.0f);
		p->side_plus = 0.5f;
	}
	s->nportal_tris += ntris;
	s->nportals++;
	return AJAR_OK;
}

ajar_status scene_add_light(Scene *s, const char *what, const ajar_light *l)
{
	const float *num[] = {l->position, l->direction, l->color};
	for (int k = 0; k < 3; k++)
		for (int j = 0; j < 3; j++)
			if (!(k == 2 ? isfinite(num[k][j]) : fabsf(num[k][j]) <= SCENE_MAX_COORD))
				return err_set(AJAR_ERROR_BAD_INPUT,
					       "%s: %s: position, direction or colour is not finite (or beyond 1e18)",
					       s->source, what);
	if (l->type != AJAR_LIGHT_DIRECTIONAL && l->type != AJAR_LIGHT_POINT && l->type != AJAR_LIGHT_SPOT)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: unknown light type %d", s->source, what, (int)l->type);
	if (!(l->color[0] >= 0.0f && l->color[1] >= 0.0f && l->color[2] >= 0.0f))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: colour (%g, %g, %g) must be >= 0", s->source, what,
			       l->color[0], l->color[1], l->color[2]);
	if (!(l->intensity >= 0.0f) || !isfinite(l->intensity))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: intensity %g must be finite and >= 0", s->source, what,
			       l->intensity);
	if (!(l->range >= 0.0f) || !isfinite(l->range))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: range %g must be finite and > 0 (0: infinite)", s->source,
			       what, l->range);
	V3 d = v3(l->direction[0], l->direction[1], l->direction[2]);
	if (l->type != AJAR_LIGHT_POINT && !(v3_len2(d) > 1e-20f))
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: zero direction", s->source, what);
	if (l->type == AJAR_LIGHT_SPOT &&
	    !(l->inner_cone >= 0.0f && l->inner_cone <= l->outer_cone && l->outer_cone > 0.0f &&
	      l->outer_cone <= 0.5f * AJAR_PI + 1e-6f))
		/* inner = outer (a hard edge) is what Blender exports for a spot without blend. */
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: %s: spot cone angles %g, %g must be 0 <= inner <= outer <= pi/2, outer > 0",
			       s->source, what, l->inner_cone, l->outer_cone);
	ajar_status st = grow32((void **)&s->lights, &s->cap_lights, (size_t)s->nlights + 1, sizeof *s->lights);
	if (st)
		return st;
	ajar_light *o = &s->lights[s->nlights++];
	*o = *l;
	if (v3_len2(d) > 1e-20f) {
		d = v3_norm(d);
		o->direction[0] = d.x + 0.0f; /* no -0, which would print as -0.000 */
		o->direction[1] = d.y + 0.0f;
		o->direction[2] = d.z + 0.0f;
	} else {
		o->direction[0] = o->direction[1] = 0.0f;
		o->direction[2] = -1.0f;
	}
	return AJAR_OK;
}

ajar_status scene_set_camera(Scene *s, V3 pos, V3 forward, V3 up, float yfov, float aspect)
{
	const float c[9] = {pos.x, pos.y, pos.z, forward.x, forward.y, forward.z, up.x, up.y, up.z};
	if (!all_finite(c, 9))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT,
			       "%s: camera: position or orientation is not finite (or beyond 1e18)", s->source);
	if (!(yfov > 0.0f && yfov < AJAR_PI))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: camera: yfov %g is not in (0, pi)", s->source,
			       yfov);
	if (!(aspect >= 0.0f) || !isfinite(aspect))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: camera: aspect ratio %g is not >= 0", s->source,
			       aspect);
	if (!(v3_len2(forward) > 0.0f))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: camera: zero view direction", s->source);
	V3 f = v3_norm(forward);
	/* Keep only the part of `up` orthogonal to the view direction, so the
	 * camera basis is orthonormal whatever the caller passes. */
	V3 u = v3_madd(up, f, -v3_dot(up, f));
	if (!(v3_len2(u) > 1e-12f * v3_len2(up)) || !(v3_len2(up) > 0.0f))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: camera: up vector is zero or parallel to the view",
			       s->source);
	s->has_camera = 1;
	s->cam_pos = pos;
	s->cam_forward = f;
	s->cam_up = v3_norm(u);
	s->cam_yfov = yfov;
	s->cam_aspect = aspect;
	return AJAR_OK;
}

void scene_set_env_color(Scene *s, V3 rgb)
{
	free(s->env_rgb);
	s->env_rgb = NULL;
	s->env_width = s->env_height = 0;
	s->env_type = ENV_COLOR;
	s->env_color = rgb;
	s->env_strength = 1.0f;
}

/* Refuses NaN and Inf, naming the pixel, and clamps negative values to 0
 * with one warning that counts them (filtered or compressed skies from
 * real tools carry a few tiny negatives). `file` names the image for
 * messages, or NULL for pixels that came from the API. */
static ajar_status env_pixels_check(const Scene *s, const char *file, uint32_t w, float *rgb, size_t n)
{
	const char *who = file ? file : s->source;
	size_t negative = 0;
	float lowest = 0.0f;
	for (size_t i = 0; i < n; i++) {
		if (!isfinite(rgb[i])) {
			size_t px = i / 3;
			return err_set(AJAR_ERROR_BAD_INPUT,
				       "%s: environment: pixel (%zu, %zu) channel %c is %g (must be finite)", who,
				       px % w, px / w, "RGB"[i % 3], rgb[i]);
		}
		if (rgb[i] < 0.0f) {
			negative++;
			lowest = fminf(lowest, rgb[i]);
			rgb[i] = 0.0f;
		}
	}
	if (negative)
		log_msg(AJAR_LOG_WARNING, "%s: environment: %zu negative pixel value%s (lowest %g) clamped to 0", who,
			negative, negative == 1 ? "" : "s", lowest);
	return AJAR_OK;
}

static ajar_status set_env_image(Scene *s, const char *file, uint32_t w, uint32_t h, float *rgb, float strength)
{
	if (!rgb || w == 0 || h == 0) {
		free(rgb);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: environment: empty image (%ux%u)", file ? file : s->source, w,
			       h);
	}
	if (!(strength >= 0.0f) || !isfinite(strength)) {
		free(rgb);
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: environment: strength %g is not >= 0", s->source,
			       strength);
	}
	ajar_status st = env_pixels_check(s, file, w, rgb, (size_t)w * h * 3);
	if (st != AJAR_OK) {
		free(rgb);
		return st;
	}
	free(s->env_rgb);
	s->env_rgb = rgb;
	s->env_width = w;
	s->env_height = h;
	s->env_strength = strength;
	s->env_type = ENV_IMAGE;
	return AJAR_OK;
}

ajar_status scene_set_env_image(Scene *s, uint32_t w, uint32_t h, float *rgb, float strength)
{
	return set_env_image(s, NULL, w, h, rgb, strength);
}

ajar_status scene_load_env_image(Scene *s, const char *path, float strength)
{
	float *rgba = NULL;
	uint32_t w = 0, h = 0;
	if (hdr_file(path)) {
		ajar_status st = hdr_read(path, &rgba, &w, &h);
		return st ? st : set_env_image(s, path, w, h, rgba, strength);
	}
	/* The size from the header first: an environment image is held to
	 * SCENE_SKY_MAX_PIXELS before its pixels are allocated. */
	ajar_status st = exr_read_size(path, &w, &h);
	if (st)
		return st;
	if ((uint64_t)w * h > SCENE_SKY_MAX_PIXELS)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: environment: %ux%u pixels; a sky has at most %llu (16384 x 8192, 2 GiB as it is read)",
			       path, w, h, (unsigned long long)SCENE_SKY_MAX_PIXELS);
	st = ajar_read_exr(path, &rgba, &w, &h);
	if (st)
		return st;
	/* Reuse the RGBA allocation for the packed RGB the scene keeps. */
	size_t n = (size_t)w * h;
	for (size_t i = 0; i < n; i++)
		for (size_t c = 0; c < 3; c++)
			rgba[3 * i + c] = rgba[4 * i + c];
	return set_env_image(s, path, w, h, rgba, strength);
}

ajar_status scene_set_env_rotation(Scene *s, double degrees)
{
	if (!isfinite(degrees))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "%s: environment: rotation %g is not a finite angle",
			       s->source, degrees);
	/* Reduced in double, so large angles keep their precision. */
	double r = fmod(degrees, 360.0);
	s->env_rotation = (float)(r * (AJAR_PI / 180.0));
	return AJAR_OK;
}

/* Min and max that take -0 below +0, so bounds do not depend on the order
 * of the triangles (a renderer puts them in its BVH's), inline: a
 * 10M-triangle scene's bounds in 40 ms, not 0.4 s of library calls. */
static inline float min_signed(float a, float b) { return b < a || (b == a && signbit(b)) ? b : a; }
static inline float max_signed(float a, float b) { return b > a || (b == a && !signbit(b)) ? b : a; }
static inline V3 v3_min_signed(V3 a, V3 b) { return v3(min_signed(a.x, b.x), min_signed(a.y, b.y), min_signed(a.z, b.z)); }
static inline V3 v3_max_signed(V3 a, V3 b) { return v3(max_signed(a.x, b.x), max_signed(a.y, b.y), max_signed(a.z, b.z)); }

static void bounds_grow(const Tri *t, V3 *lo, V3 *hi)
{
	*lo = v3_min_signed(*lo, v3_min_signed(t->p0, v3_min_signed(t->p1, t->p2)));
	*hi = v3_max_signed(*hi, v3_max_signed(t->p0, v3_max_signed(t->p1, t->p2)));
}

void scene_mesh_bounds(const Scene *s, uint32_t k, V3 *lo, V3 *hi)
{
	*lo = v3(AJAR_INF, AJAR_INF, AJAR_INF);
	*hi = v3(-AJAR_INF, -AJAR_INF, -AJAR_INF);
	const SceneMesh *m = &s->meshes[k];
	for (uint32_t i = m->first; i < m->first + m->count; i++)
		bounds_grow(&s->tris[i], lo, hi);
}

/* The float next below (dir < 0) or above a double's rounding. */
static float round_out(double v, int dir)
{
	float f = (float)v;
	if (dir < 0 && (double)f > v)
		f = nextafterf(f, -INFINITY);
	if (dir > 0 && (double)f < v)
		f = nextafterf(f, INFINITY);
	return f;
}

void scene_instance_bounds(const SceneInstance *in, V3 mlo, V3 mhi, V3 *lo, V3 *hi)
{
	double l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (int c = 0; c < 8; c++) {
		double p[3] = {c & 1 ? mhi.x : mlo.x, c & 2 ? mhi.y : mlo.y, c & 4 ? mhi.z : mlo.z};
		for (int r = 0; r < 3; r++) {
			double w = in->m[4 * r] * p[0] + in->m[4 * r + 1] * p[1] + in->m[4 * r + 2] * p[2] + in->m[4 * r + 3];
			l[r] = fmin(l[r], w);
			h[r] = fmax(h[r], w);
		}
	}
	*lo = v3(round_out(l[0], -1), round_out(l[1], -1), round_out(l[2], -1));
	*hi = v3(round_out(h[0], 1), round_out(h[1], 1), round_out(h[2], 1));
}

void scene_bounds(const Scene *s, V3 *bmin, V3 *bmax)
{
	V3 lo = v3(AJAR_INF, AJAR_INF, AJAR_INF), hi = v3(-AJAR_INF, -AJAR_INF, -AJAR_INF);
	uint32_t i = 0;
	for (uint32_t k = 0; k <= s->nmeshes; k++) { /* the flat triangles before mesh k */
		uint32_t end = k < s->nmeshes ? s->meshes[k].first : s->ntris;
		for (; i < end; i++)
			bounds_grow(&s->tris[i], &lo, &hi);
		if (k < s->nmeshes)
			i = s->meshes[k].first + s->meshes[k].count;
	}
	if (s->ninstances) {
		V3 *mb = malloc(sizeof *mb * 2 * s->nmeshes);
		for (uint32_t k = 0; mb && k < s->nmeshes; k++)
			scene_mesh_bounds(s, k, &mb[2 * k], &mb[2 * k + 1]);
		for (uint32_t j = 0; mb && j < s->ninstances; j++) {
			const SceneInstance *in = &s->instances[j];
			if (!s->meshes[in->mesh].count)
				continue;
			V3 a, b;
			scene_instance_bounds(in, mb[2 * in->mesh], mb[2 * in->mesh + 1], &a, &b);
			lo = v3_min_signed(lo, a);
			hi = v3_max_signed(hi, b);
		}
		free(mb);
	}
	for (uint32_t k = 0; k < s->nportal_tris; k++) {
		const PortalTri *t = &s->portals[k];
		lo = v3_min(lo, v3_min(t->p0, v3_min(t->p1, t->p2)));
		hi = v3_max(hi, v3_max(t->p0, v3_max(t->p1, t->p2)));
	}
	if (lo.x > hi.x)
		lo = hi = v3(0.0f, 0.0f, 0.0f);
	*bmin = lo;
	*bmax = hi;
}

SceneView scene_surface_view(const Scene *s)
{
	SceneView v;
	memset(&v, 0, sizeof v);
	v.tris = s->tris;
	v.shade = s->shade;
	v.extra = s->extra;
	v.materials = s->materials;
	v.textures = s->textures;
	v.texels = s->texels;
	return v;
}

uint32_t scene_count_emissive(const Scene *s)
{
	uint32_t n = 0;
	SceneView v = scene_surface_view(s);
	EmitMask mask;
	if (emit_mask_build(&mask, s->textures, s->ntextures, s->texels, s->materials, s->nmaterials) != AJAR_OK)
		err_clear(); /* without the tables, the texels are read */
	for (uint32_t i = 0; i < s->ntris; i++) {
		int m = s->tris[i].material;
		if (m >= 0 && (uint32_t)m < s->nmaterials && !v3_is_zero(s->materials[m].emission) &&
		    (!s->materials[m].emissive_tex || emit_mask_can_emit(&mask, &v, i, s->materials[m].emissive_tex - 1)))
			n++;
	}
	emit_mask_free(&mask);
	return n;
}

void scene_camera(const Scene *s, V3 *pos, V3 *forward, V3 *up, float *yfov)
{
	if (s->has_camera) {
		*pos = s->cam_pos;
		*forward = s->cam_forward;
		*up = s->cam_up;
		*yfov = s->cam_yfov;
		return;
	}
	V3 lo, hi;
	scene_bounds(s, &lo, &hi);
	V3 c = v3_scale(v3_add(lo, hi), 0.5f);
	float r = 0.5f * v3_len(v3_sub(hi, lo));
	if (!(r > 0.0f))
		r = 1.0f;
	float fov = 45.0f * AJAR_PI / 180.0f;
	/* Far enough that the bounding sphere fits the vertical field of view. */
	float d = r / sin(0.5f * fov);
	*pos = v3(c.x, c.y, c.z + d);
	*forward = v3(0.0f, 0.0f, -1.0f);
	*up = v3(0.0f, 1.0f, 0.0f);
	*yfov = fov;
}
