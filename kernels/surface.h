/* surface.h — what integrators know about a ray hit: position, geometric
 * and shading normals, material, its textures (base colour, metallic-
 * roughness, emission) and the BSDF they make.
 *
 * The geometric normal is the CCW front face's (glTF's front), not flipped
 * toward the ray: emitters emit from the front, and the BSDF decides sides
 * itself. The shading normal is flipped onto the geometric normal's side so
 * interpolated normals never point through the surface. */
#ifndef AJAR_SURFACE_H
#define AJAR_SURFACE_H
#include "bsdf.h"
#include "bvh.h"
#include "types.h"

typedef struct {
	V3 p;
	V3 ng;        /* unit geometric normal, front face */
	V3 ns;        /* unit shading normal, same side as ng */
	float tu, tv;   /* texture coordinates, TEXCOORD_0 */
	float tu1, tv1; /* TEXCOORD_1 (0 where the mesh has none) */
	V3 color;       /* COLOR_0 (1 where the mesh has none) */
	float alpha;    /* COLOR_0's alpha */
	int tri;
	int material;
} Surface;

INLINE float srgb_to_linear(float c)
{
	return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

/* One texel's four channels in [0, 1], colour decoded from sRGB if asked. */
typedef struct {
	V3 rgb;
	float a;
} Rgba;

INLINE Rgba texel_rgba(uint t, int srgb)
{
	Rgba r;
	float c[3];
	for (int i = 0; i < 3; i++) {
		float x = (float)((t >> (8 * i)) & 255u) * (1.0f / 255.0f);
		c[i] = srgb ? srgb_to_linear(x) : x;
	}
	r.rgb = v3(c[0], c[1], c[2]);
	r.a = (float)(t >> 24) * (1.0f / 255.0f);
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
 * blends decoded (linear) values. */
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
		return texel_rgba(px[y * t->width + x], srgb);
	}
	float x = u * (float)t->width - 0.5f, y = v * (float)t->height - 0.5f;
	float fx = floor(x), fy = floor(y);
	float ax = x - fx, ay = y - fy;
	int x0 = texture_wrap((int)fx, t->width, ws), x1 = texture_wrap((int)fx + 1, t->width, ws);
	int y0 = texture_wrap((int)fy, t->height, wt), y1 = texture_wrap((int)fy + 1, t->height, wt);
	Rgba c00 = texel_rgba(px[y0 * t->width + x0], srgb), c10 = texel_rgba(px[y0 * t->width + x1], srgb);
	Rgba c01 = texel_rgba(px[y1 * t->width + x0], srgb), c11 = texel_rgba(px[y1 * t->width + x1], srgb);
	return rgba_lerp(rgba_lerp(c00, c10, ax), rgba_lerp(c01, c11, ax), ay);
}

INLINE void surface_from_hit(const SceneView *sc, const Hit *h, Surface *s)
{
	GLOBAL const Tri *t = &sc->tris[h->tri];
	GLOBAL const TriShade *sh = &sc->shade[h->tri];
	float w = 1.0f - h->u - h->v;
	s->p = v3_add(v3_add(v3_scale(t->p0, w), v3_scale(t->p1, h->u)), v3_scale(t->p2, h->v));
	s->ng = v3_norm(tri_normal(t));
	s->ns = s->ng;
	if (sh->has_normals) {
		V3 n = v3_add(v3_add(v3_scale(sh->n0, w), v3_scale(sh->n1, h->u)), v3_scale(sh->n2, h->v));
		float len2 = v3_len2(n);
		if (len2 > 1e-12f) {
			n = v3_scale(n, 1.0f / sqrt(len2));
			s->ns = v3_dot(n, s->ng) < 0.0f ? v3_neg(n) : n;
		}
	}
	s->tu = w * sh->u0 + h->u * sh->u1 + h->v * sh->u2;
	s->tv = w * sh->v0 + h->u * sh->v1 + h->v * sh->v2;
	s->tu1 = s->tv1 = 0.0f;
	s->color = v3(1.0f, 1.0f, 1.0f);
	s->alpha = 1.0f;
	if (t->flags & TRI_EXTRA) {
		GLOBAL const TriExtra *e = &sc->extra[h->tri];
		s->tu1 = w * e->u0 + h->u * e->u1 + h->v * e->u2;
		s->tv1 = w * e->v0 + h->u * e->v1 + h->v * e->v2;
		float c[4];
		for (int k = 0; k < 4; k++)
			c[k] = w * e->c0[k] + h->u * e->c1[k] + h->v * e->c2[k];
		s->color = v3(c[0], c[1], c[2]);
		s->alpha = c[3];
	}
	s->tri = h->tri;
	s->material = t->material;
}

/* Whether the segment between surface points a and b (geometric normals
 * na, nb, either side) is unoccluded. Both ends are pushed off their
 * surfaces first and the ray stops short of the far end by a relative
 * margin, so neither end's own triangle counts as a blocker: measuring
 * the length from an offset origin but to an un-offset end lets the
 * target's own surface block short segments. */
INLINE int segment_clear(const SceneView *sc, V3 a, V3 na, V3 b, V3 nb)
{
	V3 d = v3_sub(b, a);
	V3 o = ray_offset(a, na, d), q = ray_offset(b, nb, v3_neg(d));
	V3 od = v3_sub(q, o);
	float len = v3_len(od);
	if (!(len > 0.0f))
		return 0;
	return !bvh_occluded(sc, o, v3_scale(od, 1.0f / len), len * (1.0f - 1e-4f));
}

/* Texture `tex` where surface s lies, in the coordinate set it reads. */
INLINE Rgba surface_texture(const SceneView *sc, const Surface *s, int tex, int srgb)
{
	if (sc->textures[tex].flags & TEX_UV1)
		return texture_rgba(sc, tex, s->tu1, s->tv1, srgb);
	return texture_rgba(sc, tex, s->tu, s->tv, srgb);
}

/* Factor x texture (sRGB) x COLOR_0 (glTF 3.9.2). */
INLINE V3 surface_base_color(const SceneView *sc, const Surface *s)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	V3 c = v3_mul(m->base_color, s->color);
	if (m->base_tex < 0)
		return c;
	return v3_mul(c, surface_texture(sc, s, m->base_tex, 1).rgb);
}

/* The BSDF at s with base colour `base` (surface_base_color): metallic and
 * roughness are the factors times the metallic-roughness texture's blue
 * and green channels (glTF 3.9.2), read without sRGB decoding. */
INLINE void surface_bsdf(const SceneView *sc, const Surface *s, V3 base, Bsdf *bs)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	float metallic = m->metallic, roughness = m->roughness;
	if (m->mr_tex) {
		Rgba t = surface_texture(sc, s, m->mr_tex - 1, 0);
		metallic *= t.rgb.z;
		roughness *= t.rgb.y;
	}
	bsdf_setup_mr(bs, m, base, metallic, roughness, s->ns, s->ng);
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
		if (sc->tris[tri].flags & TRI_EXTRA) {
			GLOBAL const TriExtra *e = &sc->extra[tri];
			u = w * e->u0 + b1 * e->u1 + b2 * e->u2;
			v = w * e->v0 + b1 * e->v1 + b2 * e->v2;
		}
	}
	return texture_rgba(sc, tex, u, v, srgb);
}
#endif
