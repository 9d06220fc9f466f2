/* gltf_load.c — the glTF loader's entry points (gltf.h): gltf.cpp parses
 * the file into a plain C document (gltf_doc.h), then the extensions are
 * checked, the materials read, the default scene's nodes walked into the
 * Scene (gltf_loader.h's parts) and its extras read. */
#include "scene/gltf.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/gltf_loader.h"
#include "scene/gltf_parts.h"

/* Required extensions Ajar does not implement are refused; every other
 * used one it does not read gets one warning (a material's are named per
 * material by gltf_materials.c). */
static ajar_status check_extensions(const GltfLoader *L)
{
	const GltfDoc *d = L->doc;
	for (size_t i = 0; i < d->nextensions_required; i++) {
		GltfString ext = d->extensions_required[i];
		if (!gltf_extension_supported(ext.s, ext.len))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "extensionsRequired: %s is not supported", ext.s);
	}
	for (size_t i = 0; i < d->nextensions_used; i++) {
		GltfString ext = d->extensions_used[i];
		int known = gltf_extension_supported(ext.s, ext.len);
		for (size_t m = 0; m < d->nmaterials && !known; m++)
			known = gltf_member_n(&d->materials[m].extensions, ext.s, ext.len) != NULL;
		if (!known)
			log_msg(AJAR_LOG_WARNING, "%s: extensionsUsed: %s is not supported; ignored", L->file, ext.s);
	}
	return AJAR_OK;
}

/* The default scene's root nodes (*owned to free), or without scenes every
 * node nobody lists as a child; `where` names them, *extras the scene's. */
static ajar_status scene_roots(const GltfLoader *L, const int **roots, size_t *nroots, int **owned, char where[64],
			       const GltfValue **extras)
{
	const GltfDoc *d = L->doc;
	*owned = NULL;
	*extras = NULL;
	snprintf(where, 64, "nodes");
	if (d->nscenes) {
		int si = d->default_scene >= 0 ? d->default_scene : 0;
		if ((size_t)si >= d->nscenes)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "scene: scenes[%d] does not exist (%zu scenes)", si,
					 d->nscenes);
		*roots = d->scenes[si].nodes.v;
		*nroots = d->scenes[si].nodes.n;
		*extras = &d->scenes[si].extras;
		snprintf(where, 64, "scenes[%d]", si);
		return AJAR_OK;
	}
	char *child = calloc(d->nnodes + 1, 1);
	int *r = malloc(d->nnodes * sizeof *r + 1);
	if (!child || !r) {
		free(child);
		free(r);
		return gltf_out_of_memory(L);
	}
	for (size_t i = 0; i < d->nnodes; i++)
		for (size_t k = 0; k < d->nodes[i].children.n; k++) {
			int c = d->nodes[i].children.v[k];
			if (c >= 0 && (size_t)c < d->nnodes)
				child[c] = 1;
		}
	size_t n = 0;
	for (size_t i = 0; i < d->nnodes; i++)
		if (!child[i])
			r[n++] = (int)i;
	free(child);
	*roots = *owned = r;
	*nroots = n;
	return AJAR_OK;
}

static ajar_status load(GltfLoader *L)
{
	const GltfDoc *d = L->doc;
	ajar_status st = check_extensions(L);
	if (st)
		return st;
	L->image_textures = malloc(d->nimages * sizeof *L->image_textures + 1);
	L->material_ids = calloc(d->nmaterials + 1, sizeof *L->material_ids);
	L->mesh_uses = calloc(d->nmeshes + 1, sizeof *L->mesh_uses);
	L->mesh_id = malloc(d->nmeshes * sizeof *L->mesh_id + 1);
	L->mesh_inst = calloc(d->nmeshes + 1, 1);
	if (!L->image_textures || !L->material_ids || !L->mesh_uses || !L->mesh_id || !L->mesh_inst)
		return gltf_out_of_memory(L);
	for (size_t i = 0; i < d->nimages; i++)
		L->image_textures[i] = -1;
	for (size_t i = 0; i < d->nmeshes; i++)
		L->mesh_id[i] = -1;
	if ((st = gltf_load_materials(L)))
		return st;

	const int *roots = NULL;
	int *owned = NULL;
	size_t nroots = 0;
	char where[64];
	const GltfValue *extras;
	if ((st = scene_roots(L, &roots, &nroots, &owned, where, &extras)))
		return st;
	if (!(st = gltf_count_mesh_uses(L, roots, nroots)))
		st = gltf_walk_nodes(L, roots, nroots, where);
	free(owned);
	if (st)
		return st;
	if (extras && ((st = gltf_read_resolution(L, extras, where)) || (st = gltf_read_environment(L, extras, where))))
		return st;
	if (scene_rendered_triangles(L->s) == 0)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: no triangles to render%s", where,
				 L->s->nportal_tris ? " (portals do not count)" : "");
	return AJAR_OK;
}

ajar_status gltf_load(const char *path, Scene **out)
{
	return gltf_load_with(path, 0, out);
}

ajar_status gltf_load_with(const char *path, int allow_outside_files, Scene **out)
{
	return gltf_load_instancing(path, allow_outside_files, GLTF_INSTANCING_AUTO, out);
}

ajar_status gltf_load_instancing(const char *path, int allow_outside_files, int instancing, Scene **out)
{
	*out = NULL;
	Scene *s = NULL;
	ajar_status st = scene_new(path, &s);
	if (st)
		return st;
	GltfLoader L;
	memset(&L, 0, sizeof L);
	L.file = path;
	L.s = s;
	L.default_material = -1;
	L.allow_outside = allow_outside_files != 0;
	L.instancing = instancing;
	const char *slash = strrchr(path, '/');
	size_t n = slash ? (size_t)(slash - path) : 1;
	char *dir = malloc(n + 2);
	char real[PATH_MAX];
	if (!dir) {
		scene_free(s);
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	}
	snprintf(dir, n + 2, "%.*s", (int)n, slash ? path : ".");
	if (!dir[0])
		snprintf(dir, n + 2, "/");
	L.dir = dir;
	L.root = realpath(dir, real) ? real : dir;
	GltfDoc *doc = NULL;
	st = gltf_doc_load(path, L.dir, L.root, L.allow_outside, &doc);
	if (!st) {
		L.doc = doc;
		st = load(&L);
	}
	gltf_doc_free(doc);
	free(L.image_textures);
	free(L.material_ids);
	free(L.mesh_uses);
	free(L.mesh_id);
	free(L.mesh_inst);
	free(dir);
	if (st) {
		scene_free(s);
		return st;
	}
	*out = s;
	return AJAR_OK;
}
