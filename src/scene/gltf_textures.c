/* gltf_textures.c — a material's textures as scene texture uses: the
 * image's texels as RGBA8 (each image converted once), the sampler's wrap
 * modes and magnification filter (there are no mipmaps: pixel sampling
 * filters), the coordinate set and KHR_texture_transform. */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "scene/gltf_parts.h"

/* images[i] as a scene texture (RGBA8), converted once. */
static ajar_status image_texture(GltfLoader *L, int i, int *id)
{
	if (L->image_textures[i] >= 0) {
		*id = L->image_textures[i];
		return AJAR_OK;
	}
	const GltfImage *im = &L->doc->images[i];
	int bytes = im->bits == 16 ? 2 : im->bits == 8 ? 1 : 0;
	if (im->width <= 0 || im->height <= 0 || im->component < 1 || im->component > 4 || !bytes)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "images[%d]: not decoded (%dx%d, %d channels of %d bits)", i,
				 im->width, im->height, im->component, im->bits);
	size_t n = (size_t)im->width * (size_t)im->height, comp = (size_t)im->component;
	if (im->size < n * comp * (size_t)bytes)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "images[%d]: %zu bytes of pixels, expected %zu", i, im->size,
				 n * comp * (size_t)bytes);
	uint8_t *rgba = malloc(n * 4);
	if (!rgba)
		return gltf_out_of_memory(L);
	gltf_rgba8(im->pixels, n, comp, bytes, rgba);
	uint32_t tid;
	ajar_status st = scene_add_texture(L->s, (uint32_t)im->width, (uint32_t)im->height, rgba, &tid);
	free(rgba);
	if (st)
		return st;
	L->image_textures[i] = (int)tid;
	*id = (int)tid;
	return AJAR_OK;
}

/* A number, or a JSON array of n numbers, of a KHR_texture_transform;
 * 0 where malformed, out untouched where absent. */
static int transform_numbers(const GltfValue *ext, const char *key, int n, double *out)
{
	const GltfValue *v = gltf_member(ext, key);
	if (!v)
		return 1;
	if (n == 1) {
		if (v->type != GLTF_VALUE_NUMBER || !isfinite(v->number))
			return 0;
		out[0] = v->number;
		return 1;
	}
	if (v->type != GLTF_VALUE_ARRAY || v->count != (size_t)n)
		return 0;
	for (int i = 0; i < n; i++) {
		const GltfValue *x = gltf_item(v, (size_t)i);
		if (x->type != GLTF_VALUE_NUMBER || !isfinite(x->number))
			return 0;
		out[i] = x->number;
	}
	return 1;
}

static int wrap_mode(int gl)
{
	return gl == GLTF_WRAP_CLAMP_TO_EDGE     ? TEX_WRAP_CLAMP
	       : gl == GLTF_WRAP_MIRRORED_REPEAT ? TEX_WRAP_MIRROR
						 : TEX_WRAP_REPEAT;
}

/* KHR_texture_transform as xf (uv' = T(offset) R(rotation) S(scale) uv)
 * and its texCoord replacing *texcoord. */
static ajar_status texture_transform(const GltfLoader *L, int mi, const char *slot, const GltfValue *ext, float xf[6],
				     int *texcoord)
{
	double off[2] = {0.0, 0.0}, rot = 0.0, sc[2] = {1.0, 1.0}, tc = *texcoord;
	if (!transform_numbers(ext, "offset", 2, off) || !transform_numbers(ext, "rotation", 1, &rot) ||
	    !transform_numbers(ext, "scale", 2, sc) || !transform_numbers(ext, "texCoord", 1, &tc) ||
	    !(tc >= 0.0 && tc == floor(tc)))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
				 "materials[%d].%s.extensions.KHR_texture_transform: offset and scale must be 2 numbers, "
				 "rotation a number, texCoord an integer >= 0",
				 mi, slot);
	/* R = [cos sin; -sin cos] in (u, v): counter-clockwise as the image is
	 * seen (v grows downwards), which TextureTransformTest's markers
	 * confirm (the other sign hits its red "opposite" marker). */
	double c = cos(rot), sn = sin(rot);
	xf[0] = (float)(c * sc[0]);
	xf[1] = (float)(sn * sc[1]);
	xf[2] = (float)off[0];
	xf[3] = (float)(-sn * sc[0]);
	xf[4] = (float)(c * sc[1]);
	xf[5] = (float)off[1];
	*texcoord = (int)fmin(tc, 1e6);
	return AJAR_OK;
}

ajar_status gltf_texture_use(GltfLoader *L, int mi, const char *slot, int index, int texcoord, const GltfValue *exts,
			     int *id)
{
	*id = -1;
	if (index < 0)
		return AJAR_OK;
	const GltfDoc *d = L->doc;
	if ((size_t)index >= d->ntextures)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d].%s: textures[%d] does not exist (%zu textures)", mi,
				 slot, index, d->ntextures);
	const GltfTexture *tex = &d->textures[index];
	if (tex->source < 0 || (size_t)tex->source >= d->nimages)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "textures[%d]: images[%d] does not exist (%zu images)", index,
				 tex->source, d->nimages);
	int flags = 0;
	if (tex->sampler >= 0) {
		if ((size_t)tex->sampler >= d->nsamplers)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "textures[%d]: samplers[%d] does not exist (%zu samplers)",
					 index, tex->sampler, d->nsamplers);
		const GltfSampler *sm = &d->samplers[tex->sampler];
		flags |= wrap_mode(sm->wrap_s) | wrap_mode(sm->wrap_t) << 2;
		if (sm->mag_filter == GLTF_FILTER_NEAREST)
			flags |= TEX_NEAREST;
	}
	float xf[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
	const GltfValue *tt = gltf_member(exts, "KHR_texture_transform");
	ajar_status st;
	if (tt && (st = texture_transform(L, mi, slot, tt, xf, &texcoord)))
		return st;
	if (texcoord > 1) {
		log_msg(AJAR_LOG_WARNING,
			"%s: materials[%d].%s uses TEXCOORD_%d; only TEXCOORD_0 and _1 are supported, texture ignored",
			L->file, mi, slot, texcoord);
		return AJAR_OK;
	}
	if (texcoord == 1)
		flags |= TEX_UV1;
	int img = -1;
	st = image_texture(L, tex->source, &img);
	uint32_t tid;
	if (!st)
		st = scene_add_texture_use(L->s, (uint32_t)img, flags, xf, &tid);
	if (!st)
		*id = (int)tid;
	return st;
}

ajar_status gltf_ext_texture(GltfLoader *L, int mi, const GltfValue *exts, const char *ext, const char *key, int *id)
{
	static const GltfValue no_extensions = {GLTF_VALUE_OBJECT, 0, 0.0, {"", 0}, 0, NULL, NULL};
	*id = -1;
	const GltfValue *info = gltf_member(gltf_member(exts, ext), key);
	if (!info)
		return AJAR_OK;
	const GltfValue *index = gltf_member(info, "index"), *texcoord = gltf_member(info, "texCoord");
	if (!index || index->type != GLTF_VALUE_NUMBER || (texcoord && texcoord->type != GLTF_VALUE_NUMBER))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s needs a numeric index (and texCoord)", mi,
				 ext, key);
	const GltfValue *own = gltf_member(info, "extensions");
	if (!own || own->type != GLTF_VALUE_OBJECT)
		own = &no_extensions;
	char slot[96];
	snprintf(slot, sizeof slot, "%s.%s", ext, key);
	return gltf_texture_use(L, mi, slot, (int)index->number, texcoord ? (int)texcoord->number : 0, own, id);
}
