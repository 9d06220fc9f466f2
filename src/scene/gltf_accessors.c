/* gltf_accessors.c — accessors' elements out of their buffer views:
 * tinygltf checks neither that a view lies inside its buffer nor that an
 * accessor lies inside its view, so every range is checked here, and
 * interleaved, sparse and view-less accessors become packed elements. */
#include "scene/gltf_loader.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf_parts.h"

/* Points *p at bytes [offset, offset + need) of bufferViews[v], after
 * checking that the view lies inside its buffer and the range inside the
 * view. */
static ajar_status view_range(const GltfLoader *L, const char *what, int v, size_t offset, size_t need,
			      const uint8_t **p)
{
	const GltfDoc *d = L->doc;
	if (v < 0 || (size_t)v >= d->nbuffer_views)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: bufferViews[%d] does not exist (%zu buffer views)", what, v,
				 d->nbuffer_views);
	const GltfBufferView *bv = &d->buffer_views[v];
	if (bv->buffer < 0 || (size_t)bv->buffer >= d->nbuffers)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "bufferViews[%d]: buffers[%d] does not exist (%zu buffers)", v,
				 bv->buffer, d->nbuffers);
	size_t have = d->buffers[bv->buffer].size;
	if (bv->byte_length > have || bv->byte_offset > have - bv->byte_length)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
				 "bufferViews[%d]: needs %zu bytes at offset %zu but buffers[%d] has %zu", v, bv->byte_length,
				 bv->byte_offset, bv->buffer, have);
	if (offset > bv->byte_length || need > bv->byte_length - offset)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: needs %zu bytes at offset %zu but bufferViews[%d] has %zu",
				 what, need, offset, v, bv->byte_length);
	*p = d->buffers[bv->buffer].data + bv->byte_offset + offset;
	return AJAR_OK;
}

/* Sparse values replace elements of p (`what` names the accessor). */
static ajar_status apply_sparse(const GltfLoader *L, const char *what, const GltfAccessor *a, size_t elem,
				GltfPacked *p)
{
	int itype = a->sparse_indices_type, isize = gltf_component_size(itype);
	if (a->sparse_count < 0 || (size_t)a->sparse_count > a->count || a->sparse_indices_offset < 0 ||
	    a->sparse_values_offset < 0 || isize == 0 || itype == GLTF_BYTE || itype == GLTF_SHORT || itype == GLTF_FLOAT)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: invalid sparse (count %d, index type %d)", what,
				 a->sparse_count, itype);
	size_t n = (size_t)a->sparse_count;
	char swhat[600];
	const uint8_t *isrc = NULL, *vsrc = NULL;
	snprintf(swhat, sizeof swhat, "%s: sparse.indices", what);
	ajar_status st = view_range(L, swhat, a->sparse_indices_view, (size_t)a->sparse_indices_offset,
				    n * (size_t)isize, &isrc);
	if (st)
		return st;
	snprintf(swhat, sizeof swhat, "%s: sparse.values", what);
	st = view_range(L, swhat, a->sparse_values_view, (size_t)a->sparse_values_offset, n * elem, &vsrc);
	if (st)
		return st;
	for (size_t k = 0; k < n; k++) {
		uint32_t i = 0;
		if (isize == 1) {
			i = isrc[k];
		} else if (isize == 2) {
			uint16_t v;
			memcpy(&v, isrc + 2 * k, 2);
			i = v;
		} else {
			memcpy(&i, isrc + 4 * k, 4);
		}
		if (i >= a->count)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: sparse index %u out of range (%zu elements)", what, i,
					 a->count);
		memcpy(&p->bytes[i * elem], vsrc + k * elem, elem);
	}
	return AJAR_OK;
}

ajar_status gltf_accessor_read(const GltfLoader *L, const char *ctx, const char *attr, int idx, int ncomp,
			       GltfPacked *p)
{
	const GltfDoc *d = L->doc;
	memset(p, 0, sizeof *p);
	if (idx < 0 || (size_t)idx >= d->naccessors)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s: accessors[%d] does not exist (%zu accessors)", ctx, attr,
				 idx, d->naccessors);
	char what[512];
	snprintf(what, sizeof what, "%s: accessors[%d] (%s)", ctx, idx, attr);
	const GltfAccessor *a = &d->accessors[idx];
	int csize = gltf_component_size(a->component_type), nc = gltf_type_components(a->type);
	if (!csize)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: unsupported componentType %d", what, a->component_type);
	if (nc != ncomp)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: has type %d, expected %d components", what, a->type, ncomp);
	if (a->count > (size_t)INT32_MAX)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: count %zu is too large", what, a->count);
	size_t elem = (size_t)csize * (size_t)nc;
	p->count = a->count;
	p->ctype = a->component_type;
	p->ncomp = nc;
	p->normalized = a->normalized;

	if (a->buffer_view >= 0) {
		if ((size_t)a->buffer_view >= d->nbuffer_views)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: bufferViews[%d] does not exist (%zu buffer views)",
					 what, a->buffer_view, d->nbuffer_views);
		size_t stride = d->buffer_views[a->buffer_view].byte_stride;
		if (stride == 0)
			stride = elem;
		/* glTF caps byteStride at 252; the cap also keeps the sizes below
		 * far from overflow. */
		if (stride < elem || stride > 252)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
					 "%s: byteStride %zu of bufferViews[%d] does not fit %zu-byte elements", what, stride,
					 a->buffer_view, elem);
		size_t need = a->count ? stride * (a->count - 1) + elem : 0;
		const uint8_t *src = NULL;
		ajar_status st = view_range(L, what, a->buffer_view, a->byte_offset, need, &src);
		if (st)
			return st;
		if (!(p->bytes = malloc(a->count * elem + 1)))
			return gltf_out_of_memory(L);
		for (size_t i = 0; i < a->count; i++)
			memcpy(&p->bytes[i * elem], src + i * stride, elem);
	} else {
		/* No buffer view: all zeros, unless sparse values replace some. No
		 * data bounds the count here, so a sanity limit does. */
		if (a->count > ((size_t)1 << 24))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "%s: %zu elements without a bufferView", what, a->count);
		if (!(p->bytes = calloc(a->count * elem + 1, 1)))
			return gltf_out_of_memory(L);
	}
	return a->is_sparse ? apply_sparse(L, what, a, elem, p) : AJAR_OK;
}

void gltf_packed_free(GltfPacked *p)
{
	free(p->bytes);
	p->bytes = NULL;
}

ajar_status gltf_packed_floats(const GltfLoader *L, const GltfPacked *p, GltfFloats *out)
{
	out->n = p->count * (size_t)p->ncomp;
	if (!(out->v = malloc(out->n * sizeof(float) + 1)))
		return gltf_out_of_memory(L);
	gltf_to_floats(p->bytes, out->n, p->ctype, p->normalized, out->v);
	return AJAR_OK;
}

ajar_status gltf_packed_indices(const GltfLoader *L, const char *ctx, int acc, const GltfPacked *p, uint32_t **out)
{
	*out = NULL;
	if (p->ctype != GLTF_UNSIGNED_BYTE && p->ctype != GLTF_UNSIGNED_SHORT && p->ctype != GLTF_UNSIGNED_INT)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
				 "%s: accessors[%d] (indices): componentType %d is not an unsigned integer", ctx, acc,
				 p->ctype);
	if (!(*out = malloc(p->count * sizeof(uint32_t) + 1)))
		return gltf_out_of_memory(L);
	gltf_to_indices(p->bytes, p->count, gltf_component_size(p->ctype), *out);
	return AJAR_OK;
}
