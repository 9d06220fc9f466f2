/* portal_find_rays.c — the search's rays: the first solid hit, free
 * segments, lit points, directions about a normal; trimmed ranges of
 * distances. */
#include "prepare/portal_find_parts.h"

int pf_trace(Ctx *c, V3 o, V3 d, float tmax, Solid *s)
{
	float acc = 0.0f;
	for (int k = 0; k < 16; k++) {
		Hit h;
		c->rays++;
		if (!bvh_intersect(c->v, o, d, tmax - acc, &h))
			break;
		GLOBAL const Tri *tri = &c->v->tris[h.tri];
		GLOBAL const Material *m = &c->v->materials[tri->material];
		V3 p = v3_madd(o, d, h.t), ng = hit_normal(c->v, &h); /* through its instance, if any */
		if (m->transmission > 0.0f) { /* glass counts as open */
			o = ray_offset(p, ng, d);
			acc += h.t;
			continue;
		}
		float side = v3_dot(ng, d);
		s->t = acc + h.t;
		s->p = p;
		s->ng = v3_norm(side < 0.0f ? ng : v3_neg(ng));
		s->emit = side < 0.0f && !v3_is_zero(m->emission);
		return 1;
	}
	s->t = AJAR_INF;
	s->emit = 0;
	return 0;
}

/* Whether the segment a -> b is free (b excluded). */
int pf_clear(Ctx *c, V3 a, V3 b)
{
	V3 d = v3_sub(b, a);
	float l = v3_len(d);
	if (!(l > 0.0f))
		return 1;
	Solid s;
	return !pf_trace(c, a, v3_scale(d, 1.0f / l), l * 0.9999f, &s);
}

/* Whether light point l lights a surface point p with normal n (facing
 * where the ray came from). */
int pf_lit_by(Ctx *c, V3 p, V3 n, const LightPoint *l)
{
	V3 to = v3_sub(l->p, p);
	if (!(v3_dot(to, n) > 0.0f))
		return 0;
	if (!v3_is_zero(l->n) && !(v3_dot(to, l->n) < 0.0f))
		return 0;
	return pf_clear(c, v3_madd(p, n, 1e-4f * c->R), l->p);
}

V3 pf_dir_about(Rng *r, V3 n, int cosine)
{
	if (!cosine)
		return sample_uniform_sphere(rnd(r), rnd(r));
	V3 t, b;
	v3_basis(n, &t, &b);
	float u1 = rnd(r), u2 = rnd(r);
	return v3_norm(v3_from_local(sample_cosine_hemisphere(u1, u2), t, b, n));
}

/* The k-th smallest of a[0..n) (reorders a). */
static float select_k(float *a, int n, int k)
{
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		float piv = a[(lo + hi) / 2];
		int i = lo, j = hi;
		while (i <= j) {
			while (a[i] < piv)
				i++;
			while (a[j] > piv)
				j--;
			if (i <= j) {
				float t = a[i];
				a[i] = a[j];
				a[j] = t;
				i++;
				j--;
			}
		}
		if (k <= j)
			hi = j;
		else if (k >= i)
			lo = i;
		else
			break;
	}
	return a[k];
}

/* The trimmed range [q, 1 - q] of a[0..n) (reorders a). */
void pf_trimmed(float *a, int n, float q, float *lo, float *hi)
{
	int k = (int)(q * (float)n);
	*lo = select_k(a, n, k);
	*hi = select_k(a, n, n - 1 - k);
}
