/* bsdf_eval_lobes.h — f and densities of the core's lobes (metal, plastic,
 * glass, thin glass) in a local frame, bent normals included. */
#ifndef AJAR_BSDF_EVAL_LOBES_H
#define AJAR_BSDF_EVAL_LOBES_H
#include "material/bsdf_frame.h"

/* Non-delta f and pdf in the frame flipped to wo (wo.z > 0). wi.z > 0 is
 * reflection, wi.z < 0 transmission; the caller has checked the sides.
 * Where the frame is a bent one (bsdf.h's top), the glossy lobes' f is scaled
 * by gr (the light side's cosine ratio) and the diffuse base keeps the
 * own normal n: its f is there where fz, the light side's cosine with n,
 * is positive, and its density is that of cosine sampling about n at
 * pz, wi's cosine with n. In the own frame gr = 1 and fz = pz = wi.z.
 * With fd, the diffuse-like part of f (the diffuse base and the
 * multiple-scattering lobes) is added to *fd too, for the layers above
 * (bsdf.h's top); f itself is computed as without. */
INLINE V3 bsdf_eval_lobes(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w, float gr, float fz,
			  float pz, V3 *fd)
{
	V3 f = v3(0.0f, 0.0f, 0.0f);
	float pdf = 0.0f;
	if (bsdf_lambert(bs)) { /* the common case, exactly what the lobes below give */
		*pdf_w = pdf_cosine_hemisphere_w(pz);
		f = wi.z > 0.0f && fz > 0.0f ? v3_scale(bs->base_color, AJAR_INV_PI) : f;
		if (fd)
			*fd = v3_add(*fd, f);
		return f;
	}
	BsdfLobes p = bsdf_lobes(bs, wo, eta);
	int smooth = bsdf_smooth(bs);
	if (wi.z > 0.0f) {
		V3 h = v3_norm(v3_add(wo, wi));
		float cos_oh = v3_dot(wo, h);
		float jac = 1.0f / (4.0f * cos_oh); /* dh / dwi for reflection */
		float inv4 = 1.0f / (4.0f * wo.z * wi.z);
		if (!smooth && bsdf_w_metal(bs) > 0.0f) {
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs)) {
				float spec = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay) * inv4;
				f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec * gr);
				pdf += p.metal * ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay) * jac;
			} else
#endif
			{
				float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4;
				f = v3_madd(f, bsdf_fresnel_metal(bs, cos_oh), bsdf_w_metal(bs) * spec * gr);
			}
			f = v3_madd(f, bs->metal_fms, bsdf_w_metal(bs) * bsdf_ms_factor(bs, p.e_metal, wi) * gr);
			if (fd)
				*fd = v3_madd(*fd, bs->metal_fms, bsdf_w_metal(bs) * bsdf_ms_factor(bs, p.e_metal, wi) * gr);
			if (!BSDF_IS_ANISO(bs))
				pdf += p.metal * ggx_pdf_visible(wo, h, bs->alpha) * jac;
		}
		pdf += p.ms * pdf_cosine_hemisphere_w(wi.z); /* metal and coat multiple scattering */
		float wp = bsdf_w_plastic(bs);
#ifndef AJAR_NO_LAYERS
		if (wp > 0.0f && BSDF_IS_TINT(bs)) { /* per channel (bsdf_setup_tint) */
			float a = bsdf_coat_alpha(bs), d = ggx_d(h, a) * ggx_g2(wo, wi, a), pv = ggx_pdf_visible(wo, h, a);
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs)) {
				d = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay);
				pv = ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay);
			}
#endif
			float e1_o, e1_i, sw = bsdf_schlick_w(cos_oh);
			float es_o = bsdf_coat_albedo_w(bs, wo, &e1_o), es_i = bsdf_coat_albedo_w(bs, wi, &e1_i);
			/* Ew from Es = s1 E1 + sw Ew with the untinted s1, sw */
			float ew_o = (es_o - bs->coat_s1 * e1_o) / fmax(bs->coat_sw, 1e-7f);
			float ew_i = (es_i - bs->coat_s1 * e1_i) / fmax(bs->coat_sw, 1e-7f);
			float kc = bsdf_kc_factor(e1_o, e1_i, bs->coat_e1avg);
			float s1[3] = {bs->tint_s1.x, bs->tint_s1.y, bs->tint_s1.z};
			float fm[3] = {bs->tint_fms.x, bs->tint_fms.y, bs->tint_fms.z};
			float ea[3] = {bs->tint_eavg.x, bs->tint_eavg.y, bs->tint_eavg.z};
			float bc[3] = {bs->base_color.x, bs->base_color.y, bs->base_color.z}, fc[3], dc[3];
			for (int c = 0; c < 3; c++) {
				float swc = bs->specular - s1[c];
				float et_o = s1[c] * e1_o + swc * ew_o + fm[c] * (1.0f - e1_o);
				float et_i = s1[c] * e1_i + swc * ew_i + fm[c] * (1.0f - e1_i);
				float kd = fz > 0.0f ? (1.0f - et_o) * (1.0f - et_i) * AJAR_INV_PI / fmax(1.0f - ea[c], 1e-7f) : 0.0f;
				dc[c] = wp * (fm[c] * kc * gr + bc[c] * kd);
				fc[c] = wp * (d * inv4 * (s1[c] + swc * sw)) * gr + dc[c];
			}
			f = v3_add(f, v3(fc[0], fc[1], fc[2]));
			if (fd)
				*fd = v3_add(*fd, v3(dc[0], dc[1], dc[2]));
			pdf += p.coat * pv * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
			wp = 0.0f; /* done */
		}
#endif
		if (wp > 0.0f) {
			float a = bsdf_coat_alpha(bs);
			float spec = ggx_d(h, a) * ggx_g2(wo, wi, a) * inv4 * bsdf_fresnel_coat(bs, cos_oh);
#ifndef AJAR_NO_ANISOTROPY
			float pv = 0.0f;
			if (BSDF_IS_ANISO(bs)) {
				spec = ggx_d_aniso(h, bs->ax, bs->ay) * ggx_g2_aniso(wo, wi, bs->ax, bs->ay) * inv4 *
				       bsdf_fresnel_coat(bs, cos_oh);
				pv = ggx_pdf_visible_aniso(wo, h, bs->ax, bs->ay);
			}
#endif
			float kd = AJAR_INV_PI, ms = 0.0f;
			if (bs->specular > 0.0f) {
				float e1_i, es_i = bsdf_coat_albedo_w(bs, wi, &e1_i);
				float kc = bsdf_kc_factor(p.e_coat1, e1_i, bs->coat_e1avg);
				spec += bs->coat_fms * kc;
				ms = bs->coat_fms * kc; /* for fd */
				kd = bsdf_base_factor(bs, bsdf_coat_total(bs, p.e_coat, p.e_coat1), bsdf_coat_total(bs, es_i, e1_i));
			}
			kd = fz > 0.0f ? kd : 0.0f;
			float ws = wp * spec * gr;
			f = v3_add(f, v3_madd(v3(ws, ws, ws), bs->base_color, wp * kd));
			if (fd) {
				float wm = wp * ms * gr;
				*fd = v3_add(*fd, v3_madd(v3(wm, wm, wm), bs->base_color, wp * kd));
			}
#ifndef AJAR_NO_ANISOTROPY
			if (BSDF_IS_ANISO(bs))
				pdf += p.coat * pv * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
			else
#endif
				pdf += p.coat * ggx_pdf_visible(wo, h, a) * jac + p.diffuse * pdf_cosine_hemisphere_w(pz);
		}
		if (!smooth && bsdf_w_glass(bs) > 0.0f) {
			int thin = bsdf_thin(bs);
			float fr = bsdf_fresnel_dielectric(cos_oh, thin ? bs->ior : eta);
			float spec = ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * inv4 * fr;
			float ms = thin ? bs->glass_x * bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wi.z), bs->glass_y)
					: bsdf_glass_ms(bs, eta > 1.0f, 1, p.e_glass, wi.z);
			float wg = bsdf_w_glass(bs) * (spec + ms) * gr;
			f = v3_add(f, v3(wg, wg, wg));
			if (fd) {
				float wgm = bsdf_w_glass(bs) * ms * gr;
				*fd = v3_add(*fd, v3(wgm, wgm, wgm));
			}
			pdf += p.glass * fr * ggx_pdf_visible(wo, h, bs->alpha) * jac + p.glass_r * pdf_cosine_hemisphere_w(wi.z);
		}
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f && bsdf_thin(bs)) {
		/* Thin: the reflection lobe at wi mirrored to wo's side, (1 - F). */
		V3 wm = v3(wi.x, wi.y, -wi.z);
		V3 h = v3_norm(v3_add(wo, wm));
		float cos_oh = v3_dot(wo, h);
		float fr = bsdf_fresnel_dielectric(cos_oh, bs->ior);
		float t = ggx_d(h, bs->alpha) * ggx_g2(wo, wm, bs->alpha) * (1.0f - fr) / (4.0f * wo.z * wm.z);
		t += (1.0f - bs->glass_x) * bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wm.z), bs->glass_y);
		f = v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr);
		if (fd)
			*fd = v3_add(*fd, v3_scale(bs->base_color, bsdf_w_glass(bs) * (1.0f - bs->glass_x) *
								  bsdf_kc_factor(p.e_glass, bsdf_metal_albedo(bs, wm.z), bs->glass_y) * gr));
		pdf = p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) / (4.0f * cos_oh) +
		      p.glass_t * pdf_cosine_hemisphere_w(wm.z);
	} else if (wi.z < 0.0f && !smooth && bsdf_w_glass(bs) > 0.0f) {
		V3 h;
		float t = bsdf_glass_ms(bs, eta > 1.0f, 0, p.e_glass, -wi.z);
		if (fd)
			*fd = v3_add(*fd, v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr *
								  (mode == BSDF_RADIANCE ? 1.0f / (eta * eta) : 1.0f)));
		pdf = p.glass_t * pdf_cosine_hemisphere_w(-wi.z);
		if (bsdf_half_refract(wo, wi, eta, &h)) {
			float cos_oh = v3_dot(wo, h), cos_ih = v3_dot(wi, h);
			/* Fresnel from the rarer medium's side (F(theta_i, eta) =
			 * F(theta_t, 1 / eta)): the same value whichever way the
			 * pair is evaluated, and accurate near the critical angle,
			 * where the denser side's cos_t is a steep square root. */
			float fr = eta >= 1.0f ? bsdf_fresnel_dielectric(cos_oh, eta)
					       : bsdf_fresnel_dielectric(-cos_ih, 1.0f / eta);
			float denom = cos_ih + cos_oh / eta;
			denom *= denom;
			t += ggx_d(h, bs->alpha) * ggx_g2(wo, wi, bs->alpha) * (1.0f - fr) *
			     fabs(cos_ih * cos_oh / (wo.z * wi.z * denom));
			pdf += p.glass * (1.0f - fr) * ggx_pdf_visible(wo, h, bs->alpha) * fabs(cos_ih) / denom;
		}
		if (mode == BSDF_RADIANCE)
			t /= eta * eta;
		f = v3_scale(bs->base_color, bsdf_w_glass(bs) * t * gr);
	}
	*pdf_w = pdf;
	return f;
}

/* bsdf_eval_lobes in the own frame. */
INLINE V3 bsdf_eval_local(const Bsdf *bs, V3 wo, V3 wi, float eta, int mode, float *pdf_w)
{
	return bsdf_eval_lobes(bs, wo, wi, eta, mode, pdf_w, 1.0f, wi.z, wi.z, 0);
}

/* Side of w as ng sees it: +1, -1, or 0 when w lies in the surface. */
INLINE float bsdf_side(const Bsdf *bs, V3 w)
{
	float c = v3_dot(w, bs->ng);
	return c > 0.0f ? 1.0f : (c < 0.0f ? -1.0f : 0.0f);
}

/* The flipped local pair for world wo, wi in frame fr, or 0 if the pair is
 * on inconsistent sides of ng and fr's normal. */
INLINE int bsdf_pair(const Bsdf *bs, const BsdfFrame *fr, V3 wo, V3 wi, V3 *lo, V3 *li, float *eta)
{
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return 0;
	*lo = bsdf_local(fr, wo, so);
	*li = bsdf_local(fr, wi, so);
	*eta = bsdf_eta(bs, so);
	if (!(lo->z > 0.0f))
		return 0;
	return so == si ? li->z > 0.0f : li->z < 0.0f;
}

/* bsdf_eval where n differs from ng (bsdf.h's top): the glossy lobes' f in the
 * camera side's normal (wo's in radiance mode, wi's in importance mode)
 * times the light side's cosine ratio, the diffuse base's in n; pdf_w
 * from wo (its normal) and, if `rev`, pdf_rev_w from wi (its normal). */
INLINE V3 bsdf_eval_bent(const Bsdf *bs, V3 wo, V3 wi, int mode, float *pdf_w, float *pdf_rev_w, int rev, V3 *fd)
{
	V3 lo, li, x, f = v3(0.0f, 0.0f, 0.0f);
	float eta, unused;
	*pdf_w = *pdf_rev_w = 0.0f;
	float so = bsdf_side(bs, wo), si = bsdf_side(bs, wi);
	if (so == 0.0f || si == 0.0f)
		return f;
	if (bsdf_keeps_n(bs, wo) && bsdf_keeps_n(bs, wi)) { /* no bend: the own frame, what the rest gives then */
		BsdfFrame fr = bsdf_frame_own(bs);
		if (bsdf_pair(bs, &fr, wo, wi, &lo, &li, &eta))
			f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, 1.0f, li.z, li.z, fd);
		if (rev && bsdf_pair(bs, &fr, wi, wo, &lo, &li, &eta))
			bsdf_eval_local(bs, lo, li, eta, mode, pdf_rev_w);
		return f;
	}
	float tn = bsdf_tilt(bs, &x);
	float to = bsdf_bend_t(bs, x, tn, wo), ti = bsdf_bend_t(bs, x, tn, wi);
	BsdfFrame fo = bsdf_frame_t(bs, x, tn, to), fi = ti == to ? fo : bsdf_frame_t(bs, x, tn, ti);
	int radiance = mode == BSDF_RADIANCE;
	float tf = radiance ? to : ti;
	V3 wl = radiance ? wi : wo;
	float gr = tf != tn ? bsdf_bend_ratio(bs, radiance ? fo.n : fi.n, wl) : 1.0f;
	float fz = so * v3_dot(wl, bs->n), pzo = so * v3_dot(wi, bs->n), pzi = si * v3_dot(wo, bs->n);
	V3 fd0 = fd ? *fd : f;
	if (bsdf_pair(bs, &fo, wo, wi, &lo, &li, &eta))
		f = bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_w, gr, fz, pzo, fd);
	if (rev && bsdf_pair(bs, &fi, wi, wo, &lo, &li, &eta))
		bsdf_eval_lobes(bs, lo, li, eta, mode, pdf_rev_w, 1.0f, pzi, pzi, 0);
	if (!radiance && ti != to) { /* the camera side is wi: f in wi's normal */
		f = v3(0.0f, 0.0f, 0.0f);
		if (fd)
			*fd = fd0;
		if (bsdf_pair(bs, &fi, wo, wi, &lo, &li, &eta))
			f = bsdf_eval_lobes(bs, lo, li, eta, mode, &unused, gr, fz, pzo, fd);
	}
	return f;
}

#endif
