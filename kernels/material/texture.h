/* texture.h — texture lookups (glTF samplers, coordinate sets,
 * KHR_texture_transform, sRGB for colour only) and the coverage (alpha)
 * of a point on a triangle, which ray traversal tests (bvh.h). */
#ifndef AJAR_TEXTURE_H
#define AJAR_TEXTURE_H
#include "base/types.h"
#include "base/fastmath.h"

/* sRGB's transfer function, the power by fastmath.h: the builtin pow is
 * generic library code on PoCL and may round differently per device. */
INLINE float srgb_to_linear(float c)
{
	return c <= 0.04045f ? c * (1.0f / 12.92f) : fast_exp(2.4f * fast_log((c + 0.055f) * (1.0f / 1.055f)));
}

/* Four channels in [0, 1]. */
typedef struct {
	V3 rgb;
	float a;
} Rgba;

/* One texel's channels as stored (colour still sRGB-encoded). */
INLINE Rgba texel_rgba(uint t)
{
	Rgba r;
	r.rgb = v3((float)(t & 255u), (float)((t >> 8) & 255u), (float)((t >> 16) & 255u));
	r.rgb = v3_scale(r.rgb, 1.0f / 255.0f);
	r.a = (float)(t >> 24) * (1.0f / 255.0f);
	return r;
}

/* The colour of a filtered value decoded from sRGB if asked (alpha is
 * linear in glTF). */
INLINE Rgba rgba_decode(Rgba r, int srgb)
{
	if (srgb)
		r.rgb = v3(srgb_to_linear(r.rgb.x), srgb_to_linear(r.rgb.y), srgb_to_linear(r.rgb.z));
	return r;
}

/* Texel index i of a row or column of n texels under a glTF wrap mode. */
INLINE int texture_wrap(int i, int n, int mode)
{
	if (mode == TEX_WRAP_CLAMP)
		return i < 0 ? 0 : (i >= n ? n - 1 : i);
	if (mode == TEX_WRAP_MIRROR) {
		int m = (i % (2 * n) + 2 * n) % (2 * n);
		return m < n ? m : 2 * n - 1 - m;
	}
	return (i % n + n) % n;
}

/* A coordinate brought into a range where texel indices stay small ints,
 * without changing what the wrap mode makes of it: one period (two for
 * mirrored repeat) for the repeating modes, just past [0, 1] for clamp. */
INLINE float texture_reduce(float u, int mode)
{
	if (mode == TEX_WRAP_CLAMP)
		return fmin(fmax(u, -1.0f), 2.0f);
	float period = mode == TEX_WRAP_MIRROR ? 2.0f : 1.0f;
	return u - period * floor(u / period);
}

INLINE Rgba rgba_lerp(Rgba a, Rgba b, float t)
{
	Rgba r;
	r.rgb = v3_add(v3_scale(a.rgb, 1.0f - t), v3_scale(b.rgb, t));
	r.a = a.a + (b.a - a.a) * t;
	return r;
}

/* Texture `tex` at (u, v), the coordinates of its set before its
 * transform: wrap modes and filter as its sampler says; (0, 0) is the
 * image's first texel's corner, as glTF defines UVs. Bilinear filtering
 * blends the stored (sRGB-encoded) values and decodes the blend, as
 * Cycles does with 8-bit sRGB images (NODE_IMAGE_COMPRESS_AS_SRGB:
 * interpolate, then color_srgb_to_linear): Blender's importer is what
 * users compare with (kernels/material/README.md, "Feature-specialised programs", "Texture coordinates and
 * samplers"). */
INLINE Rgba texture_rgba(const SceneView *sc, int tex, float u0, float v0, int srgb)
{
	GLOBAL const Texture *t = &sc->textures[tex];
	int ws = TEX_WRAP_S(t->flags), wt = TEX_WRAP_T(t->flags);
	float u = texture_reduce(t->xf[0] * u0 + t->xf[1] * v0 + t->xf[2], ws);
	float v = texture_reduce(t->xf[3] * u0 + t->xf[4] * v0 + t->xf[5], wt);
	GLOBAL const uint *px = sc->texels + t->offset;
	if (t->flags & TEX_NEAREST) {
		int x = texture_wrap((int)floor(u * (float)t->width), t->width, ws);
		int y = texture_wrap((int)floor(v * (float)t->height), t->height, wt);
		return rgba_decode(texel_rgba(px[y * t->width + x]), srgb);
	}
	float x = u * (float)t->width - 0.5f, y = v * (float)t->height - 0.5f;
	float fx = floor(x), fy = floor(y);
	float ax = x - fx, ay = y - fy;
	int x0 = texture_wrap((int)fx, t->width, ws), x1 = texture_wrap((int)fx + 1, t->width, ws);
	int y0 = texture_wrap((int)fy, t->height, wt), y1 = texture_wrap((int)fy + 1, t->height, wt);
	Rgba c00 = texel_rgba(px[y0 * t->width + x0]), c10 = texel_rgba(px[y0 * t->width + x1]);
	Rgba c01 = texel_rgba(px[y1 * t->width + x0]), c11 = texel_rgba(px[y1 * t->width + x1]);
	return rgba_decode(rgba_lerp(rgba_lerp(c00, c10, ax), rgba_lerp(c01, c11, ax), ay), srgb);
}

/* Barycentric coordinates (b1, b2) of p, a point in triangle t's plane,
 * clamped into the triangle (p = (1 - b1 - b2) p0 + b1 p1 + b2 p2). */
INLINE void tri_barycentric(GLOBAL const Tri *t, V3 p, float *b1, float *b2)
{
	V3 e1 = v3_sub(t->p1, t->p0), e2 = v3_sub(t->p2, t->p0), d = v3_sub(p, t->p0);
	float d11 = v3_dot(e1, e1), d12 = v3_dot(e1, e2), d22 = v3_dot(e2, e2);
	float d1 = v3_dot(d, e1), d2 = v3_dot(d, e2);
	float den = d11 * d22 - d12 * d12;
	float u = den > 0.0f ? (d22 * d1 - d12 * d2) / den : 0.0f;
	float v = den > 0.0f ? (d11 * d2 - d12 * d1) / den : 0.0f;
	u = fmin(fmax(u, 0.0f), 1.0f);
	v = fmin(fmax(v, 0.0f), 1.0f - u);
	*b1 = u;
	*b2 = v;
}

/* Texture `tex` at barycentric (b1, b2) of triangle `tri`. */
INLINE Rgba tri_texture(const SceneView *sc, int tri, float b1, float b2, int tex, int srgb)
{
	GLOBAL const TriShade *sh = &sc->shade[tri];
	float w = 1.0f - b1 - b2;
	float u = w * sh->u0 + b1 * sh->u1 + b2 * sh->u2;
	float v = w * sh->v0 + b1 * sh->v1 + b2 * sh->v2;
	if (sc->textures[tex].flags & TEX_UV1) {
		u = v = 0.0f;
#ifndef AJAR_NO_TRI_EXTRA
		if (sc->tris[tri].flags & TRI_EXTRA) {
			GLOBAL const TriExtra *e = &sc->extra[tri];
			u = w * e->u0 + b1 * e->u1 + b2 * e->u2;
			v = w * e->v0 + b1 * e->v1 + b2 * e->v2;
		}
#endif
	}
	return texture_rgba(sc, tex, u, v, srgb);
}
/* Alpha of triangle tri at barycentric (b1, b2): the base colour factor's
 * times the base colour texture's times COLOR_0's (glTF 3.9.2). */
INLINE float tri_alpha(const SceneView *sc, int tri, float b1, float b2)
{
	GLOBAL const Tri *t = &sc->tris[tri];
	GLOBAL const Material *m = &sc->materials[t->material];
	float a = m->base_alpha;
#ifndef AJAR_NO_TRI_EXTRA
	if (t->flags & TRI_EXTRA) {
		GLOBAL const TriExtra *e = &sc->extra[tri];
		a *= (1.0f - b1 - b2) * e->c0[3] + b1 * e->c1[3] + b2 * e->c2[3];
	}
#endif
	if (m->base_tex >= 0)
		a *= tri_texture(sc, tri, b1, b2, m->base_tex, 0).a;
	return a;
}

/* How much of a TRI_ALPHA triangle is there at (b1, b2): MASK 1 where
 * alpha reaches the cutoff, else 0; BLEND alpha. */
INLINE float tri_coverage(const SceneView *sc, int tri, float b1, float b2)
{
	GLOBAL const Material *m = &sc->materials[sc->tris[tri].material];
	float a = tri_alpha(sc, tri, b1, b2);
	if (m->flags & MATERIAL_ALPHA_MASK)
		return a >= m->alpha_cutoff ? 1.0f : 0.0f;
	return fmin(fmax(a, 0.0f), 1.0f);
}

/* A number in [0, 1) from a ray and a triangle: the stochastic
 * transparency of a BLEND surface is decided by it, so a ray query is a
 * function of its ray (the same bits every time) and different rays
 * decide independently, as pbrt-v4 hashes its rays. */
INLINE float alpha_hash(V3 o, V3 d, int tri)
{
	uint k[7] = {f2u(o.x), f2u(o.y), f2u(o.z), f2u(d.x), f2u(d.y), f2u(d.z), (uint)tri};
	uint h = 0x9e3779b9u;
	for (int i = 0; i < 7; i++) {
		h ^= k[i];
		h *= 0x85ebca6bu;
		h ^= h >> 13;
		h *= 0xc2b2ae35u;
		h ^= h >> 16;
	}
	return (float)(h >> 8) * (1.0f / 16777216.0f);
}

/* Whether a ray (o, d) meets TRI_ALPHA triangle tri at (b1, b2): where
 * its coverage is 1, always; BLEND with probability alpha. Never inlined:
 * the traversal's leaf loop (bvh.h) keeps only a flag test and a call
 * taken for alpha-tested triangles, not the texture lookup's code and
 * registers (untextured scenes: kernels/material/README.md, "Feature-specialised programs"). */
static __attribute__((noinline, unused)) int alpha_hit(const SceneView *sc, int tri, float b1, float b2, V3 o, V3 d)
{
	float c = tri_coverage(sc, tri, b1, b2);
	return c >= 1.0f || (c > 0.0f && alpha_hash(o, d, tri) < c);
}
#endif
