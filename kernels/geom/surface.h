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
#if !defined(AJAR_NO_LAYERS) || !defined(AJAR_NO_ANISOTROPY)
	V3 nu;          /* the shading normal before normal mapping (the clear coat's), ng's side */
	V3 tan;         /* TRI_TANGENT: the unit tangent, orthogonal to nu, else 0 */
	float tsign;    /* the bitangent's sign: b = tsign (nu x tan) */
#endif
} Surface;

/* Texture `tex` where surface s lies, in the coordinate set it reads. */
INLINE Rgba surface_texture(const SceneView *sc, const Surface *s, int tex, int srgb)
{
	if (sc->textures[tex].flags & TEX_UV1)
		return texture_rgba(sc, tex, s->tu1, s->tv1, srgb);
	return texture_rgba(sc, tex, s->tu, s->tv, srgb);
}

/* The interpolated tangent of hit h's TRI_TANGENT triangle in world space
 * (an instance's transform applied, a mirroring instance's bitangent
 * turned over, as the loader's flattened copy has them), made orthogonal
 * to n and unit, and the bitangent's sign; 0 if it vanishes. */
INLINE float surface_tangent(const SceneView *sc, const Hit *h, float w, V3 n, V3 *tu)
{
	GLOBAL const TriExtra *e = &sc->extra[h->tri];
	float b1 = h->u, b2 = h->v;
	V3 t = v3(w * e->t0[0] + b1 * e->t1[0] + b2 * e->t2[0], w * e->t0[1] + b1 * e->t1[1] + b2 * e->t2[1],
		  w * e->t0[2] + b1 * e->t1[2] + b2 * e->t2[2]);
	float sign = w * e->t0[3] + b1 * e->t1[3] + b2 * e->t2[3] < 0.0f ? -1.0f : 1.0f;
#ifndef AJAR_NO_INSTANCES
	if (h->inst >= 0) {
		GLOBAL const Instance *in = &sc->instances[h->inst];
		t = xf_vector(in->xf, t);
		if (in->flags & INSTANCE_MIRROR)
			sign = -sign;
	}
#endif
	t = v3_madd(t, n, -v3_dot(t, n));
	float lt = v3_len2(t);
	if (!(lt > 1e-12f))
		return 0.0f;
	*tu = v3_scale(t, 1.0f / sqrt(lt));
	return sign;
}

/* A normal map's normal at s (glTF 3.9.3): texture tex's texel (linear)
 * as a tangent-space vector, x and y times the scale, in the frame of the
 * unit tangent t (orthogonal to n; surface_tangent), sign x (n x t) and n. */
INLINE V3 surface_normal_map(const SceneView *sc, const Surface *s, V3 t, float sign, V3 n, int tex, float scale)
{
	V3 b = v3_scale(v3_cross(n, t), sign);
	V3 c = surface_texture(sc, s, tex, 0).rgb;
	V3 tn = v3((2.0f * c.x - 1.0f) * scale, (2.0f * c.y - 1.0f) * scale, 2.0f * c.z - 1.0f);
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
#if !defined(AJAR_NO_LAYERS) || !defined(AJAR_NO_ANISOTROPY)
	s->nu = v3_dot(n, s->ng) < 0.0f ? v3_neg(n) : n;
	s->tan = v3(0.0f, 0.0f, 0.0f);
	s->tsign = 0.0f;
	if (t->flags & TRI_TANGENT)
		s->tsign = surface_tangent(sc, h, w, s->nu, &s->tan);
#endif
#ifndef AJAR_NO_BENT_NORMALS
	if (t->flags & TRI_TANGENT) {
		GLOBAL const Material *m = &sc->materials[s->material];
		/* Tangents may be there for anisotropy or the clear coat's map alone. */
		if (m->normal_tex) {
#if !defined(AJAR_NO_LAYERS) || !defined(AJAR_NO_ANISOTROPY)
			/* nu is n or -n: made orthogonal to either, the tangent is the same. */
			V3 tan = s->tan;
			float sign = s->tsign;
#else
			V3 tan;
			float sign = surface_tangent(sc, h, w, n, &tan);
#endif
			if (sign != 0.0f)
				n = surface_normal_map(sc, s, tan, sign, n, m->normal_tex - 1, m->normal_scale);
		}
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

#ifndef AJAR_NO_ANISOTROPY
/* KHR_materials_anisotropy at s: the direction (1, 0) in tangent space, or
 * the texture's RG as 2c - 1, turned counter-clockwise by the rotation,
 * in the frame of the mesh's tangent; the strength times the texture's B.
 * Without a tangent (no TANGENT and no UVs to make one) the frame's own. */
INLINE void surface_anisotropy(const SceneView *sc, const Surface *s, GLOBAL const Material *m, Bsdf *bs)
{
	float strength = m->anisotropy, dx = 1.0f, dy = 0.0f, sr, cr;
#ifndef AJAR_NO_TEXTURES
	if (m->anisotropy_tex) {
		V3 c = surface_texture(sc, s, m->anisotropy_tex - 1, 0).rgb;
		dx = 2.0f * c.x - 1.0f;
		dy = 2.0f * c.y - 1.0f;
		strength *= c.z;
	}
#endif
	fast_sincos(m->anisotropy_rotation, &sr, &cr);
	float rx = cr * dx - sr * dy, ry = sr * dx + cr * dy;
	V3 dir = bs->t;
	if (s->tsign != 0.0f)
		dir = v3_add(v3_scale(s->tan, rx), v3_scale(v3_scale(v3_cross(s->nu, s->tan), s->tsign), ry));
	bsdf_setup_aniso(bs, strength, dir);
}
#endif

#ifndef AJAR_NO_LAYERS
/* KHR_materials_sheen and _clearcoat at s: factors times textures (sheen
 * colour RGB in sRGB, its roughness A; clear coat R, its roughness G), the
 * clear coat's normal its own map's, else the unmapped normal. */
INLINE void surface_layers(const SceneView *sc, const Surface *s, GLOBAL const Material *m, Bsdf *bs)
{
	V3 sheen = m->sheen_color, cn = s->nu;
	float sr = m->sheen_roughness, cc = m->clearcoat, cr = m->clearcoat_roughness;
#ifndef AJAR_NO_TEXTURES
	if (m->sheen_color_tex)
		sheen = v3_mul(sheen, surface_texture(sc, s, m->sheen_color_tex - 1, 1).rgb);
	if (m->sheen_rough_tex)
		sr *= surface_texture(sc, s, m->sheen_rough_tex - 1, 0).a;
	if (m->clearcoat_tex)
		cc *= surface_texture(sc, s, m->clearcoat_tex - 1, 0).rgb.x;
	if (m->clearcoat_rough_tex)
		cr *= surface_texture(sc, s, m->clearcoat_rough_tex - 1, 0).rgb.y;
	if (m->clearcoat_normal_tex && s->tsign != 0.0f)
		cn = surface_normal_map(sc, s, s->tan, s->tsign, s->nu, m->clearcoat_normal_tex - 1,
					m->clearcoat_normal_scale);
#endif
	bsdf_setup_layers(bs, sheen, sr, cc, cr, cn);
}
#endif

/* The BSDF at s with base colour `base` (surface_base_color): metallic and
 * roughness are the factors times the metallic-roughness texture's blue
 * and green channels (glTF 3.9.2), transmission the factor times the
 * transmission texture's red (KHR_materials_transmission), read without
 * sRGB decoding. */
INLINE void surface_bsdf(const SceneView *sc, const Surface *s, V3 base, Bsdf *bs)
{
	GLOBAL const Material *m = &sc->materials[s->material];
	float metallic = m->metallic, roughness = m->roughness, transmission = m->transmission, specular = m->specular;
#ifndef AJAR_NO_TEXTURES
	if (m->mr_tex) {
		Rgba t = surface_texture(sc, s, m->mr_tex - 1, 0);
		metallic *= t.rgb.z;
		roughness *= t.rgb.y;
	}
	if (m->transmission_tex)
		transmission *= surface_texture(sc, s, m->transmission_tex - 1, 0).rgb.x;
	if (m->specular_tex) /* KHR_materials_specular: its alpha */
		specular *= surface_texture(sc, s, m->specular_tex - 1, 0).a;
#endif
	bsdf_setup_mr(bs, m, base, metallic, roughness, transmission, specular, s->ns, s->ng);
#ifndef AJAR_NO_ANISOTROPY
	if (m->anisotropy > 0.0f)
		surface_anisotropy(sc, s, m, bs);
#endif
#ifndef AJAR_NO_LAYERS
	if (m->flags & MATERIAL_TINTED) {
		V3 tint = m->specular_color;
#ifndef AJAR_NO_TEXTURES
		if (m->specular_color_tex)
			tint = v3_mul(tint, surface_texture(sc, s, m->specular_color_tex - 1, 1).rgb);
#endif
		bsdf_setup_tint(bs, tint);
	}
	if (v3_maxc(m->sheen_color) > 0.0f || m->clearcoat > 0.0f)
		surface_layers(sc, s, m, bs);
#endif
}

#endif
