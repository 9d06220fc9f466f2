/* gltf_decode.c — a glTF file's data as the scene takes it: accessor
 * components as floats or indices, strips and fans as triangle lists,
 * image texels as RGBA8, and accessor types' sizes. The bounds are
 * gltf_accessors.c's to check first. */
#include "scene/gltf_parts.h"

#include <math.h>
#include <string.h>

int gltf_component_size(int ctype)
{
	switch (ctype) {
	case GLTF_BYTE:
	case GLTF_UNSIGNED_BYTE: return 1;
	case GLTF_SHORT:
	case GLTF_UNSIGNED_SHORT: return 2;
	case GLTF_UNSIGNED_INT:
	case GLTF_FLOAT: return 4;
	}
	return 0;
}

int gltf_type_components(int type)
{
	switch (type) {
	case GLTF_SCALAR: return 1;
	case GLTF_VEC2: return 2;
	case GLTF_VEC3: return 3;
	case GLTF_VEC4: return 4;
	}
	return 0;
}

/* One component as a float; normalized integers map to [0, 1] or [-1, 1]
 * as glTF specifies. */
static float component_float(const uint8_t *b, int ctype, int normalized)
{
	switch (ctype) {
	case GLTF_FLOAT: {
		float f;
		memcpy(&f, b, 4);
		return f;
	}
	case GLTF_BYTE: {
		int8_t v;
		memcpy(&v, b, 1);
		return normalized ? fmaxf(v / 127.0f, -1.0f) : (float)v;
	}
	case GLTF_UNSIGNED_BYTE: return normalized ? b[0] / 255.0f : (float)b[0];
	case GLTF_SHORT: {
		int16_t v;
		memcpy(&v, b, 2);
		return normalized ? fmaxf(v / 32767.0f, -1.0f) : (float)v;
	}
	case GLTF_UNSIGNED_SHORT: {
		uint16_t v;
		memcpy(&v, b, 2);
		return normalized ? v / 65535.0f : (float)v;
	}
	default: { /* UNSIGNED_INT */
		uint32_t v;
		memcpy(&v, b, 4);
		return normalized ? (float)(v / 4294967295.0) : (float)v;
	}
	}
}

void gltf_to_floats(const uint8_t *bytes, size_t n, int ctype, int normalized, float *out)
{
	int cs = gltf_component_size(ctype);
	for (size_t i = 0; i < n; i++)
		out[i] = component_float(&bytes[i * (size_t)cs], ctype, normalized);
}

void gltf_to_indices(const uint8_t *bytes, size_t n, int cs, uint32_t *out)
{
	for (size_t i = 0; i < n; i++) {
		const uint8_t *b = &bytes[i * (size_t)cs];
		if (cs == 1) {
			out[i] = b[0];
		} else if (cs == 2) {
			uint16_t v;
			memcpy(&v, b, 2);
			out[i] = v;
		} else {
			memcpy(&out[i], b, 4);
		}
	}
}

size_t gltf_unroll(int strip, const uint32_t *in, size_t n, uint32_t *out)
{
	size_t k = 0;
	for (size_t i = 0; i + 2 < n; i++) {
		uint32_t a, b, c;
		if (strip) {
			/* glTF 3.7.2.1: triangle i is (i, i + 1 + i%2, i + 2 - i%2). */
			a = in[i];
			b = in[i + 1 + i % 2];
			c = in[i + 2 - i % 2];
		} else {
			a = in[i + 1];
			b = in[i + 2];
			c = in[0];
		}
		if (a == b || b == c || a == c)
			continue;
		out[k++] = a;
		out[k++] = b;
		out[k++] = c;
	}
	return k;
}

void gltf_rgba8(const unsigned char *img, size_t n, size_t comp, int bytes, uint8_t *rgba)
{
	for (size_t p = 0; p < n; p++) {
		uint8_t v[4] = {0, 0, 0, 255};
		for (size_t c = 0; c < comp; c++) {
			if (bytes == 1) {
				v[c] = img[p * comp + c];
			} else {
				uint16_t w;
				memcpy(&w, &img[2 * (p * comp + c)], 2);
				v[c] = (uint8_t)(w >> 8);
			}
		}
		uint8_t *d = &rgba[4 * p];
		if (comp <= 2) { /* grey, grey + alpha */
			d[0] = d[1] = d[2] = v[0];
			d[3] = comp == 2 ? v[1] : 255;
		} else {
			memcpy(d, v, 4);
		}
	}
}
