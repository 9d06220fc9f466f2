/* aov.h — per-sample first-hit outputs for denoisers (albedo, normal,
 * depth) and the squared radiance a pixel's variance needs.
 *
 * Independent of the integrator: each pixel sample traces its own camera
 * ray again (the same jittered position, so the AOVs average over the same
 * pixel footprint as the image) and, through mirrors and smooth glass (the
 * delta materials, bsdf_is_delta), on to the first non-specular hit, as
 * Open Image Denoise asks of its albedo and normal images. Smooth glass is
 * followed by refraction (by reflection on total internal reflection),
 * a smooth mirror by reflection; no random numbers are used except for the
 * fixed-point rounding, drawn from a stream of its own (AOV_STREAM), so the
 * image's samples are untouched and the AOVs are the same bits whatever
 * the integrator, device, passes or resumes.
 *
 * Channels per pixel, as 64-bit fixed point like the film (film.h):
 *   0-2 albedo   base colour (textured) of the first non-specular hit
 *   3-5 normal   its world-space shading normal, turned toward the ray
 *   6   depth    distance from the camera to the first hit of any kind
 *   7-9 L^2      squared radiance of the pixel's own estimate (splats out),
 *                in AOV_SQ_SCALE steps, clamped at AOV_SQ_MAX per sample
 * A ray that escapes (or a chain longer than AOV_CHAIN) adds zeros. */
#ifndef AJAR_AOV_H
#define AJAR_AOV_H
#include "film/aov_layout.h"
#include "material/bsdf.h"
#include "geom/bvh.h"
#include "film/film.h"
#include "sample/rng.h"
#include "geom/surface.h"

#define AOV_STREAM 0x414f5631u /* "AOV1" */
#define AOV_CHAIN 8            /* delta bounces followed at most */

/* film_fixed for values of either sign (normals). */
INLINE long film_fixed_signed(float v, float u)
{
	if (!(v == v))
		return 0;
	return (long)floor(fmin(fmax(v, -FILM_MAX), FILM_MAX) * FILM_SCALE + u);
}

/* Adds sample (seed, pixel, index)'s AOVs for camera ray (o, d) and the
 * sample's own radiance L to sum[AOV_CHANNELS]. */
CALLED void aov_sample(const SceneView *sc, V3 o, V3 d, V3 L, uint pixel, uint index, long *sum)
{
	float v[AOV_CHANNELS];
	for (int c = 0; c < AOV_CHANNELS; c++)
		v[c] = 0.0f;
	V3 cam = o;
	for (int k = 0; k <= AOV_CHAIN; k++) {
		Hit h;
		if (!bvh_intersect(sc, o, d, AJAR_INF, &h))
			break;
		Surface s;
		surface_from_hit(sc, &h, &s);
		if (k == 0)
			v[6] = v3_len(v3_sub(s.p, cam));
		Bsdf bs;
		bsdf_setup(&bs, &sc->materials[s.material], surface_base_color(sc, &s), s.ns, s.ng);
		if (!bsdf_is_delta(&bs)) {
			V3 n = v3_dot(s.ns, d) > 0.0f ? v3_neg(s.ns) : s.ns;
			v[0] = bs.base_color.x;
			v[1] = bs.base_color.y;
			v[2] = bs.base_color.z;
			v[3] = n.x;
			v[4] = n.y;
			v[5] = n.z;
			break;
		}
		/* Mirror, or glass by refraction (straight through thin glass): on
		 * through the chain. */
		V3 wo = v3_neg(d), n = v3_dot(bs.n, wo) < 0.0f ? v3_neg(bs.n) : bs.n, wi;
		float side = bsdf_side(&bs, wo);
		if (bsdf_w_glass(&bs) > bsdf_w_metal(&bs) && bsdf_thin(&bs))
			wi = d;
		else if (!(bsdf_w_glass(&bs) > bsdf_w_metal(&bs)) || !bsdf_refract(wo, n, bsdf_eta(&bs, side), &wi))
			wi = bsdf_reflect(wo, n);
		o = ray_offset(s.p, s.ng, wi);
		d = wi;
	}
	V3 l = v3(fmin(fmax(L.x, 0.0f), FILM_MAX), fmin(fmax(L.y, 0.0f), FILM_MAX), fmin(fmax(L.z, 0.0f), FILM_MAX));
	Rng r = rng_init(sc->params->seed, pixel, index, AOV_STREAM);
	for (int c = 0; c < 7; c++)
		sum[c] += film_fixed_signed(v[c], rng_pcg_f(&r));
	sum[7] += (long)floor(fmin(l.x * l.x, AOV_SQ_MAX) * AOV_SQ_SCALE + rng_pcg_f(&r));
	sum[8] += (long)floor(fmin(l.y * l.y, AOV_SQ_MAX) * AOV_SQ_SCALE + rng_pcg_f(&r));
	sum[9] += (long)floor(fmin(l.z * l.z, AOV_SQ_MAX) * AOV_SQ_SCALE + rng_pcg_f(&r));
}
#endif
