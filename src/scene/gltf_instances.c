/* gltf_instances.c — a mesh node's copies (its world matrix, or one per
 * EXT_mesh_gpu_instancing instance), each flattened into world space or,
 * for a mesh kept once (gltf_instancing.c's rule), an instance of its
 * object-space triangles; emitting primitives and portal nodes stay
 * flattened (src/scene/README.md, "Instances"). */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf.h"
#include "scene/gltf_parts.h"

static const char *const instance_attributes[3] = {"TRANSLATION", "ROTATION", "SCALE"};

/* Portal markers: true, or a non-zero number (Blender custom properties). */
static int is_portal(const GltfNode *n)
{
	const GltfValue *v = gltf_member(&n->extras, "portal");
	if (!v)
		return 0;
	if (v->type == GLTF_VALUE_BOOL)
		return v->boolean;
	if (v->type == GLTF_VALUE_NUMBER)
		return v->number != 0.0;
	return 0;
}

/* Triangles the mesh's primitives make (strips and fans counted as drawn,
 * points and lines none), from their accessors' counts. */
static uint64_t mesh_triangles(const GltfLoader *L, int mi)
{
	const GltfMesh *mesh = &L->doc->meshes[mi];
	uint64_t n = 0;
	for (size_t p = 0; p < mesh->nprimitives; p++) {
		const GltfPrimitive *pr = &mesh->primitives[p];
		int mode = pr->mode < 0 ? GLTF_MODE_TRIANGLES : pr->mode;
		int acc = pr->indices;
		if (acc < 0 && !gltf_attribute(pr, "POSITION", &acc))
			acc = -1;
		if (acc < 0 || (size_t)acc >= L->doc->naccessors)
			continue;
		n += gltf_mode_triangles(mode, L->doc->accessors[acc].count);
	}
	return n;
}

/* The accessors of node ni's EXT_mesh_gpu_instancing (-1 where absent)
 * and their count; 0 without the extension. */
static int gpu_instancing(const GltfLoader *L, int ni, int acc[3], size_t *count)
{
	const GltfValue *ext = gltf_member(&L->doc->nodes[ni].extensions, "EXT_mesh_gpu_instancing");
	if (!ext)
		return 0;
	const GltfValue *attrs = gltf_member(ext, "attributes");
	*count = 0;
	for (int k = 0; k < 3; k++) {
		const GltfValue *v = gltf_member(attrs, instance_attributes[k]);
		acc[k] = v && v->type == GLTF_VALUE_NUMBER ? (int)v->number : -1;
		if (acc[k] >= 0 && (size_t)acc[k] < L->doc->naccessors)
			*count = L->doc->accessors[acc[k]].count;
	}
	return 1;
}

/* The transforms of node ni's copies into *out (16 doubles each, *n of
 * them): its world matrix, or with EXT_mesh_gpu_instancing world x T x R
 * x S of each instance. */
static ajar_status node_copies(GltfLoader *L, int ni, const double world[16], double **out, size_t *n)
{
	int acc[3];
	size_t count = 0;
	*out = NULL;
	*n = 0;
	if (!gpu_instancing(L, ni, acc, &count)) {
		if (!(*out = malloc(16 * sizeof(double))))
			return gltf_out_of_memory(L);
		memcpy(*out, world, 16 * sizeof(double));
		*n = 1;
		return AJAR_OK;
	}
	char ctx[64];
	snprintf(ctx, sizeof ctx, "nodes[%d]: EXT_mesh_gpu_instancing", ni);
	if (acc[0] < 0 && acc[1] < 0 && acc[2] < 0)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: no TRANSLATION, ROTATION or SCALE", ctx);
	GltfFloats v[3] = {{NULL, 0}, {NULL, 0}, {NULL, 0}};
	ajar_status st = AJAR_OK;
	for (int k = 0; k < 3 && !st; k++) {
		if (acc[k] < 0)
			continue;
		GltfPacked p;
		st = gltf_accessor_read(L, ctx, instance_attributes[k], acc[k], k == 1 ? 4 : 3, &p);
		if (!st && p.count != count)
			st = gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s has %zu elements, the others %zu", ctx,
				       instance_attributes[k], p.count, count);
		if (!st)
			st = gltf_packed_floats(L, &p, &v[k]);
		gltf_packed_free(&p);
	}
	if (!st && !(*out = malloc(16 * count * sizeof(double) + 1)))
		st = gltf_out_of_memory(L);
	for (size_t i = 0; i < count && !st; i++) {
		double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
		for (int c = 0; c < 3 && v[0].n; c++)
			t[c] = v[0].v[3 * i + (size_t)c];
		for (int c = 0; c < 4 && v[1].n; c++)
			q[c] = v[1].v[4 * i + (size_t)c];
		for (int c = 0; c < 3 && v[2].n; c++)
			sc[c] = v[2].v[3 * i + (size_t)c];
		double local[16];
		if (!(st = gltf_trs(L, ctx, t, q, sc, local)))
			gltf_mat_mul(world, local, &(*out)[16 * i]);
	}
	for (int k = 0; k < 3; k++)
		free(v[k].v);
	if (!st)
		*n = count;
	return st;
}

/* Whether primitive pi of mesh mi emits: its triangles stay world-space
 * copies, each an emitter of the light tables, never an instance's. */
static int primitive_emits(const GltfLoader *L, int mi, int pi)
{
	int m = L->doc->meshes[mi].primitives[pi].material;
	if (m < 0 || (size_t)m >= L->doc->nmaterials)
		return 0;
	return v3_lum(L->s->materials[L->material_ids[m]].emission) > 0.0f;
}

/* Mesh mi's primitives that do not emit, once, in object space: the
 * scene mesh its instances draw (-2 if it makes no triangles). */
static ajar_status load_instanced_mesh(GltfLoader *L, int mi)
{
	double id[16], nm[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	gltf_mat_identity(id);
	uint32_t first = L->s->ntris;
	const GltfMesh *mesh = &L->doc->meshes[mi];
	for (size_t p = 0; p < mesh->nprimitives; p++) {
		if (primitive_emits(L, mi, (int)p))
			continue;
		ajar_status st = gltf_load_primitive(L, mi, (int)p, id, nm, 0, NULL);
		if (st)
			return st;
	}
	L->mesh_id[mi] = -2;
	if (L->s->ntris == first)
		return AJAR_OK;
	char what[32];
	snprintf(what, sizeof what, "meshes[%d]", mi);
	uint32_t id_out;
	ajar_status st = scene_add_mesh_range(L->s, what, first, &id_out);
	if (!st)
		L->mesh_id[mi] = (int)id_out;
	return st;
}

/* One copy of node ni's mesh under `world`: an instance of its object-space
 * mesh (and world-space copies of its emitting primitives), or all of it
 * flattened; a portal node's triangles go to `portal`. */
static ajar_status load_mesh_copy(GltfLoader *L, int ni, const double world[16], GltfPortalMesh *portal)
{
	int mi = L->doc->nodes[ni].mesh;
	double nm[3][3];
	double det = gltf_normal_matrix(world, nm);
	if (!(fabs(det) > 0.0) || !isfinite(det)) {
		log_msg(AJAR_LOG_WARNING, "%s: nodes[%d]: transform is singular (zero scale), mesh skipped", L->file, ni);
		return AJAR_OK;
	}
	const GltfMesh *mesh = &L->doc->meshes[mi];
	int inst = !portal && L->mesh_inst[mi];
	ajar_status st;
	if (inst && L->mesh_id[mi] == -1 && (st = load_instanced_mesh(L, mi)))
		return st;
	if (inst && L->mesh_id[mi] >= 0) {
		char what[48];
		snprintf(what, sizeof what, "nodes[%d]", ni);
		if ((st = scene_add_instance(L->s, what, (uint32_t)L->mesh_id[mi], world)))
			return st;
	}
	for (size_t p = 0; p < mesh->nprimitives; p++) {
		if (inst && !primitive_emits(L, mi, (int)p))
			continue;
		st = gltf_load_primitive(L, mi, (int)p, world, nm, det < 0.0, portal);
		if (st)
			return st;
	}
	return AJAR_OK;
}

/* A portal node's gathered triangles as one portal. */
static ajar_status add_portal(GltfLoader *L, int ni, const GltfPortalMesh *portal)
{
	if (!portal->nidx) {
		log_msg(AJAR_LOG_WARNING, "%s: nodes[%d]: portal has no triangles, ignored", L->file, ni);
		return AJAR_OK;
	}
	char what[64];
	snprintf(what, sizeof what, "nodes[%d] (portal)", ni);
	return scene_add_portal(L->s, what, portal->pos, (uint32_t)(portal->npos / 3), portal->idx,
				(uint32_t)(portal->nidx / 3));
}

ajar_status gltf_load_mesh_node(GltfLoader *L, int ni, const double world[16])
{
	const GltfNode *n = &L->doc->nodes[ni];
	if ((size_t)n->mesh >= L->doc->nmeshes)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: meshes[%d] does not exist (%zu meshes)", ni, n->mesh,
				 L->doc->nmeshes);
	int portal_node = is_portal(n);
	GltfPortalMesh portal;
	memset(&portal, 0, sizeof portal);
	double *copies;
	size_t ncopies;
	ajar_status st = node_copies(L, ni, world, &copies, &ncopies);
	for (size_t c = 0; c < ncopies && !st; c++)
		st = load_mesh_copy(L, ni, &copies[16 * c], portal_node ? &portal : NULL);
	if (!st && portal_node)
		st = add_portal(L, ni, &portal);
	free(copies);
	free(portal.pos);
	free(portal.idx);
	return st;
}

ajar_status gltf_count_mesh_uses(GltfLoader *L, const int *roots, size_t nroots)
{
	const GltfDoc *d = L->doc;
	char *seen = calloc(d->nnodes + 1, 1);
	size_t cap = nroots + 16, top = 0;
	int *stack = malloc(cap * sizeof *stack);
	ajar_status st = seen && stack ? AJAR_OK : gltf_out_of_memory(L);
	for (size_t r = 0; r < nroots && !st; r++)
		if (roots[r] >= 0 && (size_t)roots[r] < d->nnodes)
			stack[top++] = roots[r];
	while (top && !st) {
		int ni = stack[--top];
		if (seen[ni])
			continue;
		seen[ni] = 1;
		const GltfNode *n = &d->nodes[ni];
		if (n->mesh >= 0 && (size_t)n->mesh < d->nmeshes && !is_portal(n)) {
			int acc[3];
			size_t count = 1;
			if (!gpu_instancing(L, ni, acc, &count))
				count = 1;
			L->mesh_uses[n->mesh] += count;
		}
		if (top + n->children.n > cap) {
			cap = 2 * (top + n->children.n);
			int *grown = realloc(stack, cap * sizeof *stack);
			if (!grown) {
				st = gltf_out_of_memory(L);
				break;
			}
			stack = grown;
		}
		for (size_t k = 0; k < n->children.n; k++) {
			int c = n->children.v[k];
			if (c >= 0 && (size_t)c < d->nnodes)
				stack[top++] = c;
		}
	}
	free(seen);
	free(stack);
	if (st)
		return st;
	for (size_t k = 0; k < d->nmeshes; k++)
		L->mesh_inst[k] = L->instancing == GLTF_INSTANCING_ALL	  ? L->mesh_uses[k] >= 1
				  : L->instancing == GLTF_INSTANCING_NONE ? 0
									  : gltf_mesh_instanced(mesh_triangles(L, (int)k),
												L->mesh_uses[k]);
	return AJAR_OK;
}
