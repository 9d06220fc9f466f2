/* gltf_nodes.c — the node walk: each node's local matrix (`matrix`, or
 * T R S) times its parent's, depth-first from the scene's roots in file
 * order, parents before children, so that "the first camera" is well
 * defined; a node reached twice is refused (one parent each). */
#include "scene/gltf_loader.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf_parts.h"

/* The node's local matrix: `matrix`, or T * R * S. */
static ajar_status node_local(const GltfLoader *L, int i, double m[16])
{
	const GltfNode *n = &L->doc->nodes[i];
	if (n->matrix.n) {
		if (n->matrix.n != 16)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: matrix has %zu numbers, expected 16", i,
					 n->matrix.n);
		for (int k = 0; k < 16; k++)
			m[k] = n->matrix.v[k];
		return AJAR_OK;
	}
	if ((n->translation.n && n->translation.n != 3) || (n->rotation.n && n->rotation.n != 4) ||
	    (n->scale.n && n->scale.n != 3))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: translation, rotation or scale has the wrong length",
				 i);
	double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
	for (int k = 0; k < 3 && n->translation.n; k++)
		t[k] = n->translation.v[k];
	for (int k = 0; k < 4 && n->rotation.n; k++)
		q[k] = n->rotation.v[k];
	for (int k = 0; k < 3 && n->scale.n; k++)
		s[k] = n->scale.v[k];
	char ctx[32];
	snprintf(ctx, sizeof ctx, "nodes[%d]", i);
	return gltf_trs(L, ctx, t, q, s, m);
}

/* A node to visit under its parent's world matrix. */
typedef struct {
	int node;
	double parent[16];
} Pending;

/* What node ni draws or sets under `world`: its mesh, the camera (the
 * first only), its light. */
static ajar_status load_node(GltfLoader *L, int ni, const double world[16])
{
	const GltfNode *n = &L->doc->nodes[ni];
	ajar_status st;
	if (n->mesh >= 0 && (st = gltf_load_mesh_node(L, ni, world)))
		return st;
	if (n->camera >= 0 && !L->s->has_camera && (st = gltf_load_camera_node(L, ni, world)))
		return st;
	return gltf_load_light_node(L, ni, world);
}

static ajar_status walk(GltfLoader *L, const int *roots, size_t nroots, const char *roots_what, Pending **stack,
			size_t *cap, char *seen)
{
	const size_t nn = L->doc->nnodes;
	size_t top = 0;
	for (size_t r = nroots; r-- > 0;) {
		if (roots[r] < 0 || (size_t)roots[r] >= nn)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: nodes[%d] does not exist (%zu nodes)", roots_what,
					 roots[r], nn);
		(*stack)[top].node = roots[r];
		gltf_mat_identity((*stack)[top++].parent);
	}
	while (top) {
		Pending it = (*stack)[--top];
		int ni = it.node;
		if (seen[ni])
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: reached twice (a node may have only one parent)",
					 ni);
		seen[ni] = 1;
		const GltfNode *n = &L->doc->nodes[ni];
		double local[16], world[16];
		ajar_status st = node_local(L, ni, local);
		if (st)
			return st;
		gltf_mat_mul(it.parent, local, world);
		if ((st = load_node(L, ni, world)))
			return st;
		if (top + n->children.n > *cap) {
			size_t want = 2 * (top + n->children.n);
			Pending *grown = realloc(*stack, want * sizeof **stack);
			if (!grown)
				return gltf_out_of_memory(L);
			*stack = grown;
			*cap = want;
		}
		for (size_t k = n->children.n; k-- > 0;) {
			int ch = n->children.v[k];
			if (ch < 0 || (size_t)ch >= nn)
				return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: child nodes[%d] does not exist (%zu nodes)",
						 ni, ch, nn);
			(*stack)[top].node = ch;
			memcpy((*stack)[top++].parent, world, sizeof world);
		}
	}
	return AJAR_OK;
}

ajar_status gltf_walk_nodes(GltfLoader *L, const int *roots, size_t nroots, const char *roots_what)
{
	size_t cap = nroots + 16;
	Pending *stack = malloc(cap * sizeof *stack);
	char *seen = calloc(L->doc->nnodes + 1, 1);
	ajar_status st = stack && seen ? walk(L, roots, nroots, roots_what, &stack, &cap, seen) : gltf_out_of_memory(L);
	free(stack);
	free(seen);
	return st;
}
