/* gltf_primitives.c — a mesh primitive's triangles into the scene: indices
 * (strips and fans unrolled), positions by the node's world matrix,
 * normals by its inverse transpose, winding reversed where it mirrors,
 * both texture coordinate sets, COLOR_0, and tangents for the materials
 * that need them (TANGENT, else generated: tangents.c). Points and lines
 * are skipped with a warning. */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf_parts.h"
#include "scene/tangents.h"

/* The arrays a primitive fills, freed together. */
typedef struct {
	GltfFloats pos, nrm, uv, uv1, col, tan;
	uint32_t *tri;
	size_t ntri_idx; /* indices in tri */
} Vertices;

static void vertices_free(Vertices *v)
{
	free(v->pos.v);
	free(v->nrm.v);
	free(v->uv.v);
	free(v->uv1.v);
	free(v->col.v);
	free(v->tan.v);
	free(v->tri);
}

/* Where an empty array was an empty std::vector: NULL. */
static const float *or_null(const GltfFloats *a)
{
	return a->n ? a->v : NULL;
}

/* accessors[acc] (`attr`) as floats of ncomp components, nv elements. */
static ajar_status read_floats(const GltfLoader *L, const char *what, const char *attr, int acc, int ncomp, size_t nv,
			       GltfFloats *out)
{
	GltfPacked p;
	ajar_status st = gltf_accessor_read(L, what, attr, acc, ncomp, &p);
	if (!st && p.count != nv)
		st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s has %zu elements, POSITION %zu", what, attr, p.count, nv);
	if (!st)
		st = gltf_packed_floats(L, &p, out);
	gltf_packed_free(&p);
	return st;
}

/* The primitive's index list (0 .. nv - 1 without indices) as triangles:
 * strips and fans unrolled, their degenerate stitching triangles dropped. */
static ajar_status triangle_list(const GltfLoader *L, const char *what, const GltfPrimitive *pr, int mode, size_t nv,
				 Vertices *v)
{
	uint32_t *idx = NULL;
	size_t n = nv;
	ajar_status st = AJAR_OK;
	if (pr->indices >= 0) {
		GltfPacked p;
		st = gltf_accessor_read(L, what, "indices", pr->indices, 1, &p);
		if (!st)
			st = gltf_packed_indices(L, what, pr->indices, &p, &idx);
		n = p.count;
		gltf_packed_free(&p);
		if (st)
			return st;
	} else {
		if (!(idx = malloc(nv * sizeof *idx + 1)))
			return gltf_out_of_memory(L);
		for (size_t i = 0; i < nv; i++)
			idx[i] = (uint32_t)i;
	}
	for (size_t i = 0; i < n && !st; i++)
		if (idx[i] >= nv)
			st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: index %u (at %zu) out of range (%zu vertices)", what,
				       idx[i], i, nv);
	if (!st && mode == GLTF_MODE_TRIANGLES) {
		if (n % 3) {
			st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: %zu vertices do not make whole triangles", what, n);
		} else {
			v->tri = idx;
			v->ntri_idx = n;
			return AJAR_OK;
		}
	} else if (!st) {
		if (!(v->tri = malloc((n > 2 ? 3 * (n - 2) : 0) * sizeof(uint32_t) + 1)))
			st = gltf_out_of_memory(L);
		else
			v->ntri_idx = gltf_unroll(mode == GLTF_MODE_TRIANGLE_STRIP, idx, n, v->tri);
	}
	free(idx);
	return st;
}

/* COLOR_0: RGB or RGBA, float or normalized unsigned integers, linear;
 * as RGBA clamped to [0, 1]. */
static ajar_status read_colors(const GltfLoader *L, const char *what, int acc, size_t nv, GltfFloats *col)
{
	int nc = acc >= 0 && (size_t)acc < L->doc->naccessors ? gltf_type_components(L->doc->accessors[acc].type) : 4;
	GltfPacked p;
	GltfFloats c = {NULL, 0};
	ajar_status st = gltf_accessor_read(L, what, "COLOR_0", acc, nc == 3 ? 3 : 4, &p);
	if (!st && p.count != nv)
		st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: COLOR_0 has %zu elements, POSITION %zu", what, p.count, nv);
	if (!st && p.ctype != GLTF_FLOAT && !p.normalized)
		st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: accessors[%d] (COLOR_0): integer components must be normalized",
			       what, acc);
	if (!st)
		st = gltf_packed_floats(L, &p, &c);
	if (!st && !(col->v = malloc(4 * nv * sizeof(float) + 1)))
		st = gltf_out_of_memory(L);
	if (!st) {
		col->n = 4 * nv;
		for (size_t k = 0; k < col->n; k++)
			col->v[k] = 1.0f;
		for (size_t v = 0; v < nv; v++)
			for (int j = 0; j < p.ncomp; j++)
				col->v[4 * v + (size_t)j] = fminf(fmaxf(c.v[(size_t)p.ncomp * v + (size_t)j], 0.0f), 1.0f);
	}
	free(c.v);
	gltf_packed_free(&p);
	return st;
}

/* Tangents for a normal map where the mesh has none (tangents.c) from the
 * coordinate set `set`; the vertices it splits in two are appended to
 * every per-vertex array. */
static ajar_status generate_tangents(const GltfLoader *L, Vertices *v, GltfFloats *set)
{
	size_t nv = v->pos.n / 3, total = 0;
	uint32_t *twin = malloc(nv * sizeof *twin + 1);
	float *t = NULL;
	if (!twin)
		return gltf_out_of_memory(L);
	if (tangents_generate(v->pos.v, or_null(&v->nrm), set->v, nv, v->tri, v->ntri_idx / 3, twin, &t, &total) !=
	    AJAR_OK) {
		free(twin);
		return gltf_fail(L, AJAR_ERROR_OUT_OF_MEMORY, "out of memory for tangents");
	}
	v->tan.v = t;
	v->tan.n = 4 * total;
	GltfFloats *arrays[5] = {&v->pos, &v->nrm, &v->uv, &v->uv1, &v->col};
	const size_t widths[5] = {3, 3, 2, 2, 4};
	for (int k = 0; k < 5; k++) {
		GltfFloats *a = arrays[k];
		size_t w = widths[k];
		if (!a->n)
			continue;
		float *grown = realloc(a->v, total * w * sizeof(float) + 1);
		if (!grown) {
			free(twin);
			return gltf_out_of_memory(L);
		}
		a->v = grown;
		memset(a->v + nv * w, 0, (total - nv) * w * sizeof(float));
		a->n = total * w;
		for (size_t i = 0; i < nv; i++)
			if (twin[i] != UINT32_MAX)
				memcpy(&a->v[twin[i] * w], &a->v[i * w], w * sizeof(float));
	}
	free(twin);
	return AJAR_OK;
}

/* The primitive's scene material: its own, or glTF's default. */
static ajar_status primitive_material(GltfLoader *L, const char *what, const GltfPrimitive *pr, uint32_t *mat)
{
	*mat = 0;
	if (pr->material < 0)
		return gltf_default_material(L, mat);
	if ((size_t)pr->material >= L->doc->nmaterials)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: materials[%d] does not exist (%zu materials)", what,
				 pr->material, L->doc->nmaterials);
	*mat = L->material_ids[pr->material];
	return AJAR_OK;
}

/* Tangents for a material with a normal map (or a clear coat's, or
 * anisotropy): TANGENT (xyz by the node's matrix, w turned over where it
 * mirrors), else generated from that map's coordinate set. */
static ajar_status load_tangents(const GltfLoader *L, const char *what, const GltfPrimitive *pr,
				 const double world[16], int flip, const Material *sm, Vertices *v)
{
	size_t nv = v->pos.n / 3;
	/* the set of the normal map, the clear coat's, or TEXCOORD_0 */
	int tex = sm->normal_tex ? sm->normal_tex : sm->clearcoat_normal_tex;
	GltfFloats *set = tex && (L->s->textures[tex - 1].flags & TEX_UV1) ? &v->uv1 : &v->uv;
	int acc;
	if (gltf_attribute(pr, "TANGENT", &acc)) {
		ajar_status st = read_floats(L, what, "TANGENT", acc, 4, nv, &v->tan);
		if (st)
			return st;
		gltf_transform_tangents(world, v->tan.v, nv, flip);
		return AJAR_OK;
	}
	return set->n ? generate_tangents(L, v, set) : AJAR_OK;
}

/* A portal node's triangles gathered, positions already in world space. */
static ajar_status add_to_portal(const GltfLoader *L, GltfPortalMesh *portal, const Vertices *v)
{
	uint32_t base = (uint32_t)(portal->npos / 3);
	if (portal->npos + v->pos.n > portal->pos_cap) {
		size_t cap = 2 * portal->pos_cap > portal->npos + v->pos.n ? 2 * portal->pos_cap : portal->npos + v->pos.n;
		float *p = realloc(portal->pos, cap * sizeof(float) + 1);
		if (!p)
			return gltf_out_of_memory(L);
		portal->pos = p;
		portal->pos_cap = cap;
	}
	if (portal->nidx + v->ntri_idx > portal->idx_cap) {
		size_t cap = 2 * portal->idx_cap > portal->nidx + v->ntri_idx ? 2 * portal->idx_cap : portal->nidx + v->ntri_idx;
		uint32_t *p = realloc(portal->idx, cap * sizeof(uint32_t) + 1);
		if (!p)
			return gltf_out_of_memory(L);
		portal->idx = p;
		portal->idx_cap = cap;
	}
	if (v->pos.n)
		memcpy(portal->pos + portal->npos, v->pos.v, v->pos.n * sizeof(float));
	portal->npos += v->pos.n;
	for (size_t k = 0; k < v->ntri_idx; k++)
		portal->idx[portal->nidx++] = base + v->tri[k];
	return AJAR_OK;
}

static ajar_status add_primitive(GltfLoader *L, int mi, int pi, const double world[16], const double nm[3][3],
				 int flip, GltfPortalMesh *portal, Vertices *v)
{
	const GltfPrimitive *pr = &L->doc->meshes[mi].primitives[pi];
	char what[64];
	snprintf(what, sizeof what, "meshes[%d].primitives[%d]", mi, pi);
	int mode = pr->mode < 0 ? GLTF_MODE_TRIANGLES : pr->mode;
	if (mode != GLTF_MODE_TRIANGLES && mode != GLTF_MODE_TRIANGLE_STRIP && mode != GLTF_MODE_TRIANGLE_FAN) {
		log_msg(AJAR_LOG_WARNING, "%s: %s: mode %d (points or lines) skipped", L->file, what, mode);
		return AJAR_OK;
	}
	int acc;
	if (!gltf_attribute(pr, "POSITION", &acc)) {
		log_msg(AJAR_LOG_WARNING, "%s: %s: no POSITION, skipped", L->file, what);
		return AJAR_OK;
	}
	GltfPacked pp;
	ajar_status st = gltf_accessor_read(L, what, "POSITION", acc, 3, &pp);
	if (!st)
		st = gltf_packed_floats(L, &pp, &v->pos);
	size_t nv = pp.count;
	gltf_packed_free(&pp);
	if (st || (st = triangle_list(L, what, pr, mode, nv, v)))
		return st;
	for (size_t i = 0; i < nv; i++)
		for (int c = 0; c < 3; c++)
			if (!isfinite(v->pos.v[3 * i + (size_t)c]))
				return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: vertex %zu: position is not finite", what, i);
	if (flip)
		for (size_t t = 0; t < v->ntri_idx; t += 3) {
			uint32_t k = v->tri[t + 1];
			v->tri[t + 1] = v->tri[t + 2];
			v->tri[t + 2] = k;
		}
	gltf_transform_points(world, v->pos.v, nv);
	uint32_t ntris = (uint32_t)(v->ntri_idx / 3);
	if (portal)
		return add_to_portal(L, portal, v);

	if (gltf_attribute(pr, "NORMAL", &acc)) {
		if ((st = read_floats(L, what, "NORMAL", acc, 3, nv, &v->nrm)))
			return st;
		gltf_transform_normals(nm, v->nrm.v, nv);
	}
	const char *sets[2] = {"TEXCOORD_0", "TEXCOORD_1"};
	for (int k = 0; k < 2; k++)
		if (gltf_attribute(pr, sets[k], &acc) && (st = read_floats(L, what, sets[k], acc, 2, nv, k ? &v->uv1 : &v->uv)))
			return st;
	if (gltf_attribute(pr, "COLOR_0", &acc) && (st = read_colors(L, what, acc, nv, &v->col)))
		return st;
	uint32_t mat;
	if ((st = primitive_material(L, what, pr, &mat)))
		return st;
	const Material *sm = &L->s->materials[mat];
	if ((sm->normal_tex || sm->clearcoat_normal_tex || sm->anisotropy > 0.0f) &&
	    (st = load_tangents(L, what, pr, world, flip, sm, v)))
		return st;
	nv = v->pos.n / 3;
	return scene_add_triangles_ex(L->s, what, or_null(&v->pos), or_null(&v->nrm), or_null(&v->uv), or_null(&v->uv1),
				      or_null(&v->col), or_null(&v->tan), (uint32_t)nv, v->ntri_idx ? v->tri : NULL, ntris,
				      mat);
}

ajar_status gltf_load_primitive(GltfLoader *L, int mi, int pi, const double world[16], const double nm[3][3],
				int flip, GltfPortalMesh *portal)
{
	Vertices v;
	memset(&v, 0, sizeof v);
	ajar_status st = add_primitive(L, mi, pi, world, nm, flip, portal, &v);
	vertices_free(&v);
	return st;
}
