/* surface.h — what integrators know about a ray hit: position, geometric
 * and shading normals, material and its textured base colour.
 *
 * The geometric normal is the CCW front face's (glTF's front), not flipped
 * toward the ray: emitters emit from the front, and the BSDF decides sides
 * itself. The shading normal is flipped onto the geometric normal's side so
 * interpolated normals never point through the surface. */
#ifndef AJAR_SURFACE_H
#define AJAR_SURFACE_H
#include "bvh.h"
#include "types.h"

typedef struct {
	V3 p;
	V3 ng;        /* unit geometric normal, front face */
	V3 ns;        /* unit shading normal, same side as ng */
	float tu, tv; /* texture coordinates */
	int tri;
	int material;
} Surface;

INLINE float srgb_to_linear(float c)
{
	return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

INLINE V3 texel_rgb(uint t)
{
	return v3(srgb_to_linear((float)(t & 255u) * (1.0f / 255.0f)),
		  srgb_to_linear((float)((t >> 8) & 255u) * (1.0f / 255.0f)),
		  srgb_to_linear((float)((t >> 16) & 255u) * (1.0f / 255.0f)));
}

/* Bilinear lookup with repeat wrapping; (0, 0) is the image's first texel
 * corner, as glTF defines UVs. */
INLINE V3 texture_rgb(const SceneView *sc, int tex, float u, float v)
{
	GLOBAL const Texture *t = &sc->textures[tex];
	float x = (u - floor(u)) * (float)t->width - 0.5f;
	float y = (v - floor(v)) * (float)t->height - 0.5f;
	float fx = floor(x), fy = floor(y);
	float ax = x - fx, ay = y - fy;
	int x0 = (int)fx, y0 = (int)fy;
	int x1 = x0 + 1, y1 = y0 + 1;
	x0 = (x0 % t->width + t->width) % t->width;
	x1 = x1 % t->width;
	y0 = (y0 % t->height + t->height) % t->height;
	y1 = y1 % t->height;
	GLOBAL const uint *px = sc->texels + t->offset;
	V3 c00 = texel_rgb(px[y0 * t->width + x0]), c10 = texel_rgb(px[y0 * t->width + x1]);
	V3 c01 = texel_rgb(px[y1 * t->width + x0]), c11 = texel_rgb(px[y1 * t->width + x1]);
	V3 top = v3_add(v3_scale(c00, 1.0f - ax), v3_scale(c10, ax));
	V3 bot = v3_add(v3_scale(c01, 1.0f - ax), v3_scale(c11, ax));
	return v3_add(v3_scale(top, 1.0f - ay), v3_scale(bot, ay));
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

INLINE V3 surface_base_color(const SceneView *sc, const Surface *s)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	if (m->base_tex < 0)
		return m->base_color;
	return v3_mul(m->base_color, texture_rgb(sc, m->base_tex, s->tu, s->tv));
}
#endif
