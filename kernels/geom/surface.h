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
#include "material/bsdf.h"
#include "geom/bvh.h"
#include "base/types.h"

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

/* Texture `tex` where surface s lies, in the coordinate set it reads. */
INLINE Rgba surface_texture(const SceneView *sc, const Surface *s, int tex, int srgb)
{
	if (sc->textures[tex].flags & TEX_UV1)
		return texture_rgba(sc, tex, s->tu1, s->tv1, srgb);
	return texture_rgba(sc, tex, s->tu, s->tv, srgb);
}

/* A normal map's normal at s (glTF 3.9.3): the texel (linear) as a
 * tangent-space vector, x and y times the scale, in the frame of the
 * interpolated tangent t (made orthogonal to n), sign x (n x t) and n. */
INLINE V3 surface_normal_map(const SceneView *sc, const Surface *s, V3 t, float sign, V3 n)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	t = v3_madd(t, n, -v3_dot(t, n));
	float lt = v3_len2(t);
	if (!(lt > 1e-12f))
		return n;
	t = v3_scale(t, 1.0f / sqrt(lt));
	V3 b = v3_scale(v3_cross(n, t), sign);
	V3 c = surface_texture(sc, s, m->normal_tex - 1, 0).rgb;
	V3 tn = v3((2.0f * c.x - 1.0f) * m->normal_scale, (2.0f * c.y - 1.0f) * m->normal_scale, 2.0f * c.z - 1.0f);
	V3 r = v3_add(v3_add(v3_scale(t, tn.x), v3_scale(b, tn.y)), v3_scale(n, tn.z));
	float lr = v3_len2(r);
	return lr > 1e-12f ? v3_scale(r, 1.0f / sqrt(lr)) : n;
}

/* A hit in an instance (Hit.inst) is a triangle in object space: its
 * point goes by the instance's transform, its normals by the inverse
 * transpose (each vertex normal made unit, as the loader makes a flattened
 * copy's), its tangent by the transform, and a mirroring instance turns
 * the bitangent over, so a copy shades as its flattened triangle would. */
INLINE void surface_from_hit(const SceneView *sc, const Hit *h, Surface *s)
{
	GLOBAL const Tri *t = &sc->tris[h->tri];
	GLOBAL const TriShade *sh = &sc->shade[h->tri];
#ifndef AJAR_NO_INSTANCES
	GLOBAL const Instance *in = h->inst >= 0 ? &sc->instances[h->inst] : 0;
#endif
	float w = 1.0f - h->u - h->v;
	s->p = v3_add(v3_add(v3_scale(t->p0, w), v3_scale(t->p1, h->u)), v3_scale(t->p2, h->v));
	s->ng = v3_norm(tri_normal(t));
#ifndef AJAR_NO_INSTANCES
	if (in) {
		s->p = xf_point(in->xf, s->p);
		s->ng = v3_norm(xf_normal(in->inv, tri_normal(t)));
	}
#endif
	s->tu = w * sh->u0 + h->u * sh->u1 + h->v * sh->u2;
	s->tv = w * sh->v0 + h->u * sh->v1 + h->v * sh->v2;
	s->tu1 = s->tv1 = 0.0f;
	s->color = v3(1.0f, 1.0f, 1.0f);
	s->alpha = 1.0f;
	s->tri = h->tri;
	s->material = t->material;
#ifndef AJAR_NO_TRI_EXTRA
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
#endif
	V3 n = s->ng;
	if (sh->has_normals) {
		V3 n0 = sh->n0, n1 = sh->n1, n2 = sh->n2;
#ifndef AJAR_NO_INSTANCES
		if (in) {
			n0 = v3_norm(xf_normal(in->inv, n0));
			n1 = v3_norm(xf_normal(in->inv, n1));
			n2 = v3_norm(xf_normal(in->inv, n2));
		}
#endif
		V3 ni = v3_add(v3_add(v3_scale(n0, w), v3_scale(n1, h->u)), v3_scale(n2, h->v));
		float len2 = v3_len2(ni);
		if (len2 > 1e-12f)
			n = v3_scale(ni, 1.0f / sqrt(len2));
	}
#ifndef AJAR_NO_BENT_NORMALS
	if (t->flags & TRI_TANGENT) {
		GLOBAL const TriExtra *e = &sc->extra[h->tri];
		float b1 = h->u, b2 = h->v;
		V3 tan = v3(w * e->t0[0] + b1 * e->t1[0] + b2 * e->t2[0], w * e->t0[1] + b1 * e->t1[1] + b2 * e->t2[1],
			    w * e->t0[2] + b1 * e->t1[2] + b2 * e->t2[2]);
		float sign = w * e->t0[3] + b1 * e->t1[3] + b2 * e->t2[3] < 0.0f ? -1.0f : 1.0f;
#ifndef AJAR_NO_INSTANCES
		if (in) {
			tan = xf_vector(in->xf, tan);
			if (in->flags & INSTANCE_MIRROR)
				sign = -sign;
		}
#endif
		n = surface_normal_map(sc, s, tan, sign, n);
	}
#endif
	s->ns = v3_dot(n, s->ng) < 0.0f ? v3_neg(n) : n;
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

/* Factor x texture (sRGB) x COLOR_0 (glTF 3.9.2). */
INLINE V3 surface_base_color(const SceneView *sc, const Surface *s)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	V3 c = v3_mul(m->base_color, s->color);
#ifndef AJAR_NO_TEXTURES
	if (m->base_tex >= 0)
		c = v3_mul(c, surface_texture(sc, s, m->base_tex, 1).rgb);
#endif
	return c;
}

/* The BSDF at s with base colour `base` (surface_base_color): metallic and
 * roughness are the factors times the metallic-roughness texture's blue
 * and green channels (glTF 3.9.2), transmission the factor times the
 * transmission texture's red (KHR_materials_transmission), read without
 * sRGB decoding. */
INLINE void surface_bsdf(const SceneView *sc, const Surface *s, V3 base, Bsdf *bs)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	float metallic = m->metallic, roughness = m->roughness, transmission = m->transmission;
#ifndef AJAR_NO_TEXTURES
	if (m->mr_tex) {
		Rgba t = surface_texture(sc, s, m->mr_tex - 1, 0);
		metallic *= t.rgb.z;
		roughness *= t.rgb.y;
	}
	if (m->transmission_tex)
		transmission *= surface_texture(sc, s, m->transmission_tex - 1, 0).rgb.x;
#endif
	bsdf_setup_mr(bs, m, base, metallic, roughness, transmission, s->ns, s->ng);
}

#endif
