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

/* Anisotropic GGX (KHR_materials_anisotropy): roughness ax along the
 * frame's x (the anisotropy direction), ay along y. The isotropic
 * functions above are these with ax = ay, written apart so that isotropic
 * materials keep their bits. */
INLINE float ggx_d_aniso(V3 h, float ax, float ay)
{
	if (h.z <= 0.0f)
		return 0.0f;
	float x = h.x / ax, y = h.y / ay, d = x * x + y * y + h.z * h.z;
	return 1.0f / (AJAR_PI * ax * ay * d * d);
}

INLINE float ggx_lambda_aniso(V3 w, float ax, float ay)
{
	float z2 = w.z * w.z;
	if (!(z2 > 0.0f))
		return AJAR_INF;
	float a2t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2;
	return 0.5f * (sqrt(1.0f + a2t2) - 1.0f);
}

INLINE float ggx_g2_aniso(V3 wo, V3 wi, float ax, float ay)
{
	return 1.0f / (1.0f + ggx_lambda_aniso(wo, ax, ay) + ggx_lambda_aniso(wi, ax, ay));
}

INLINE float ggx_pdf_visible_aniso(V3 wo, V3 h, float ax, float ay)
{
	float c = v3_dot(wo, h);
	if (c <= 0.0f)
		return 0.0f;
	return ggx_d_aniso(h, ax, ay) * c / ((1.0f + ggx_lambda_aniso(wo, ax, ay)) * wo.z);
}

/* Visible-normal sampling (Heitz 2018): stretch wo to the alpha = 1
 * configuration, sample the projected hemisphere as a disk whose lower half
 * is squashed by the view's slope, unstretch. Anisotropic: stretch by ax
 * along x and ay along y. */
INLINE V3 ggx_sample_visible_aniso(V3 wo, float ax, float ay, float u1, float u2)
{
	V3 vh = v3_norm(v3(ax * wo.x, ay * wo.y, wo.z));
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
	return v3_norm(v3(ax * nh.x, ay * nh.y, fmax(1e-7f, nh.z)));
}

INLINE V3 ggx_sample_visible(V3 wo, float alpha, float u1, float u2)
{
	return ggx_sample_visible_aniso(wo, alpha, alpha, u1, u2);
}

/* The "Charlie" sheen of KHR_materials_sheen (Estevez and Kulla 2017):
 * D(h) = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi), a = sheenRoughness^2,
 * normalised as sum D cos(theta_h) = 1, and their shadowing term
 * G = 1 / (1 + Lambda(mu_o) + Lambda(mu_i)) with the paper's fitted
 * Lambda (the numbers the extension's specification gives). f = colour D
 * G / (4 mu_o mu_i): no Fresnel, symmetric in its two directions. Sheen
 * roughness is clamped to SHEEN_MIN_R: below it the lobe is a sliver at
 * grazing that no table or sampler resolves. */
#define SHEEN_MIN_R 0.07f

INLINE float sheen_alpha(float r)
{
	r = fmin(fmax(r, SHEEN_MIN_R), 1.0f);
	return r * r;
}

/* D of a unit local h. */
INLINE float sheen_d(V3 h, float alpha)
{
	float inv = 1.0f / alpha, s2 = fmax(1.0f - h.z * h.z, 0.0f);
	if (!(s2 > 0.0f) || h.z <= 0.0f)
		return 0.0f;
	return (2.0f + inv) * fast_exp(0.5f * inv * fast_log(s2)) * AJAR_INV_2PI;
}

/* The fit's L(x) = a / (1 + b x^c) + d x + e, its coefficients
 * interpolated in (1 - alpha)^2 between the paper's two ends. */
INLINE float sheen_l(float x, float alpha)
{
	float t = (1.0f - alpha) * (1.0f - alpha);
	float a = 25.3245f + (21.5473f - 25.3245f) * t, b = 3.32435f + (3.82987f - 3.32435f) * t;
	float c = 0.16801f + (0.19823f - 0.16801f) * t, d = -1.27393f + (-1.97760f + 1.27393f) * t;
	float e = -4.85967f + (-4.32054f + 4.85967f) * t;
	return a / (1.0f + b * fast_exp(c * fast_log(x))) + d * x + e;
}

/* Lambda of a direction at cosine mu > 0 (mirrored about 1/2 as the paper
 * extends the fit). */
INLINE float sheen_lambda(float mu, float alpha)
{
	mu = fmin(fmax(mu, 0.0f), 1.0f);
	return mu < 0.5f ? fast_exp(sheen_l(mu, alpha)) : fast_exp(2.0f * sheen_l(0.5f, alpha) - sheen_l(1.0f - mu, alpha));
}

/* D G / (4 mu_o mu_i) for local wo, wi above the surface (colour 1). */
INLINE float sheen_f(V3 wo, V3 wi, float alpha)
{
	if (!(wo.z > 0.0f) || !(wi.z > 0.0f))
		return 0.0f;
	V3 h = v3_norm(v3_add(wo, wi));
	float g = 1.0f / (1.0f + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha));
	return sheen_d(h, alpha) * g / (4.0f * wo.z * wi.z);
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
