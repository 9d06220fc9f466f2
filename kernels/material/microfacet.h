/* microfacet.h — the pieces of a GGX microfacet BSDF that do not depend on
 * the material: Schlick's and the exact dielectric Fresnel, the GGX normal
 * distribution, Smith's Lambda and height-correlated G2, visible-normal
 * sampling and its density, reflection and refraction. bsdf.h builds the
 * glTF material from them; src/tools/bsdf_tables.c integrates them into the
 * albedo tables that bsdf.h's energy compensation reads (bsdf_tables.h), so
 * the tables are made from exactly the code the kernels evaluate. */
#ifndef AJAR_MICROFACET_H
#define AJAR_MICROFACET_H
#include "sample/sampling.h"

INLINE float bsdf_clamp01(float x) { return fmin(fmax(x, 0.0f), 1.0f); }

/* (1 - c)^5, Schlick's Fresnel weight. */
INLINE float bsdf_schlick_w(float c)
{
	float m = bsdf_clamp01(1.0f - c);
	float m2 = m * m;
	return m2 * m2 * m;
}

/* Exact unpolarised dielectric Fresnel reflectance; cos_i > 0 on the side of
 * the incident direction, eta = eta_transmitted / eta_incident. */
INLINE float bsdf_fresnel_dielectric(float cos_i, float eta)
{
	cos_i = bsdf_clamp01(cos_i);
	float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0f)
		return 1.0f; /* total internal reflection */
	float cos_t = sqrt(1.0f - sin2_t);
	float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
	float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
	return 0.5f * (r_par * r_par + r_perp * r_perp);
}

/* GGX normal distribution of a unit local h; written with the tangential
 * part so it stays accurate near h = z at tiny alpha. */
INLINE float ggx_d(V3 h, float alpha)
{
	if (h.z <= 0.0f)
		return 0.0f;
	float a2 = alpha * alpha;
	float d = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
	return a2 / (AJAR_PI * d * d);
}

/* Smith Lambda of GGX. */
INLINE float ggx_lambda(V3 w, float alpha)
{
	float z2 = w.z * w.z;
	if (!(z2 > 0.0f))
		return AJAR_INF;
	float a2t2 = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
	return 0.5f * (sqrt(1.0f + a2t2) - 1.0f);
}

INLINE float ggx_g2(V3 wo, V3 wi, float alpha)
{
	return 1.0f / (1.0f + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha));
}

/* Density of the visible normal h seen from wo (wo.z > 0):
 * G1(wo) max(0, wo.h) D(h) / wo.z. */
INLINE float ggx_pdf_visible(V3 wo, V3 h, float alpha)
{
	float c = v3_dot(wo, h);
	if (c <= 0.0f)
		return 0.0f;
	return ggx_d(h, alpha) * c / ((1.0f + ggx_lambda(wo, alpha)) * wo.z);
}

/* Visible-normal sampling (Heitz 2018): stretch wo to the alpha = 1
 * configuration, sample the projected hemisphere as a disk whose lower half
 * is squashed by the view's slope, unstretch. */
INLINE V3 ggx_sample_visible(V3 wo, float alpha, float u1, float u2)
{
	V3 vh = v3_norm(v3(alpha * wo.x, alpha * wo.y, wo.z));
	float len2 = vh.x * vh.x + vh.y * vh.y;
	V3 t1 = len2 > 1e-14f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrt(len2)) : v3(1.0f, 0.0f, 0.0f);
	V3 t2 = v3_cross(vh, t1);
	float r = sqrt(u1), sp, cp;
	fast_sincos(AJAR_PI * (2.0f * u2 - 1.0f), &sp, &cp);
	float p1 = r * cp, p2 = r * sp;
	float s = 0.5f * (1.0f + vh.z);
	p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
	V3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
		       v3_scale(vh, sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2))));
	return v3_norm(v3(alpha * nh.x, alpha * nh.y, fmax(1e-7f, nh.z)));
}

INLINE V3 bsdf_reflect(V3 w, V3 h) { return v3_sub(v3_scale(h, 2.0f * v3_dot(w, h)), w); }

/* Refraction of w (on the side h points to) through h; eta = eta_t / eta_i.
 * Returns 0 on total internal reflection. */
INLINE int bsdf_refract(V3 w, V3 h, float eta, V3 *wt)
{
	float cos_i = v3_dot(w, h);
	float sin2_t = fmax(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0f)
		return 0;
	float cos_t = sqrt(1.0f - sin2_t);
	*wt = v3_add(v3_scale(w, -1.0f / eta), v3_scale(h, cos_i / eta - cos_t));
	return 1;
}

/* Half vector of a refraction pair in the flipped frame (wo.z > 0 > wi.z):
 * Walter's generalized h, oriented to +z; 0 if degenerate or if either
 * direction is on the wrong side of the microfacet. */
INLINE int bsdf_half_refract(V3 wo, V3 wi, float eta, V3 *h)
{
	V3 m = v3_add(wo, v3_scale(wi, eta));
	float l2 = v3_len2(m);
	if (!(l2 > 1e-20f))
		return 0;
	m = v3_scale(m, 1.0f / sqrt(l2));
	if (m.z < 0.0f)
		m = v3_neg(m);
	if (!(v3_dot(wo, m) > 0.0f) || !(v3_dot(wi, m) < 0.0f))
		return 0;
	*h = m;
	return 1;
}

#endif
