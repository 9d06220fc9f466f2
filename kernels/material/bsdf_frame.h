/* bsdf_frame.h — shading frames and normals that bend toward ng where a
 * direction needs it (bsdf.h's top: shading normals that face away). */
#ifndef AJAR_BSDF_FRAME_H
#define AJAR_BSDF_FRAME_H
#include "material/bsdf_albedo.h"

/* A shading frame: the Bsdf's own, or a bent one (bsdf_bend_t). */
typedef struct {
	V3 t, b, n;
} BsdfFrame;

INLINE BsdfFrame bsdf_frame_own(const Bsdf *bs)
{
	BsdfFrame f;
	f.t = bs->t;
	f.b = bs->b;
	f.n = bs->n;
	return f;
}

/* The tilt of n from ng: *x the unit direction of n's component along the
 * surface; returns the angle tn between n and ng, n = sin tn x + cos tn ng.
 * Bent normals are kept as their angle from ng: a cosine rounds small
 * angles (1e-4) to 0. */
INLINE float bsdf_tilt(const Bsdf *bs, V3 *x)
{
	float nz = v3_dot(bs->n, bs->ng);
	V3 d = v3_madd(bs->n, bs->ng, -nz);
	float l = v3_len(d);
	*x = l > 0.0f ? v3_scale(d, 1.0f / l) : bs->t;
	return fast_atan2(l, fmax(nz, 0.0f));
}

/* Whether direction w keeps the own normal n: its mirror image about n lies
 * at least thr = min(0.9 |w . ng|, 0.01) above the surface on w's side,
 * 2 (w . n)(n . ng) - w . ng in w's side's sign (Cycles'
 * ensure_valid_specular_reflection test). By dot products alone: surfaces
 * with smooth normals ask it of every direction, and mostly keep n. */
INLINE int bsdf_keeps_n(const Bsdf *bs, V3 w)
{
	float iz = v3_dot(w, bs->ng);
	float sgn = iz < 0.0f ? -1.0f : 1.0f;
	iz *= sgn;
	float h = sgn * (2.0f * v3_dot(w, bs->n) * v3_dot(bs->n, bs->ng)) - iz;
	return h >= fmin(0.9f * iz, 0.01f);
}

/* The angle from ng of the normal that direction w needs, on the arc from
 * n (angle tn, tilt direction x) to ng: tn where w's mirror image about n
 * lies at least thr = min(0.9 |w . ng|, 0.01) above the surface (w's own
 * side), else the normal whose mirror image lies at exactly thr. With w =
 * (ix, iz) in (x, ng) (w's y does not enter) and the normal at angle t, the
 * mirror's height is 2 (w . N) cos t - iz = ix sin 2t + iz cos 2t
 * = A cos(2t - phi), A = |(ix, iz)|, phi = atan2(ix, iz): >= thr for t in
 * [0, (phi + acos(thr / A)) / 2], so every normal from there to ng keeps w
 * (and its mirror image) above it. */
INLINE float bsdf_bend_t(const Bsdf *bs, V3 x, float tn, V3 w)
{
	float iz = v3_dot(w, bs->ng);
	float sgn = iz < 0.0f ? -1.0f : 1.0f;
	iz *= sgn;
	float ix = sgn * v3_dot(w, x);
	float thr = fmin(0.9f * iz, 0.01f);
	if (bsdf_keeps_n(bs, w)) /* the height ix sin 2tn + iz cos 2tn >= thr */
		return tn;
	float a = sqrt(ix * ix + iz * iz);
	if (!(a > 0.0f))
		return 0.0f;
	/* acos c = atan2(sqrt((1 - c)(1 + c)), c), exact near c = 1 too. */
	float c = fmin(thr / a, 1.0f);
	float t = 0.5f * (fast_atan2(ix, iz) + fast_atan2(sqrt((1.0f - c) * (1.0f + c)), c));
	return fmin(fmax(t, 0.0f), tn);
}

/* The frame of the normal at angle t on the arc (the own frame at tn). */
INLINE BsdfFrame bsdf_frame_t(const Bsdf *bs, V3 x, float tn, float t)
{
	if (t == tn)
		return bsdf_frame_own(bs);
	BsdfFrame f;
	float st, ct;
	fast_sincos(t, &st, &ct); /* t in [0, pi / 2] */
	f.n = v3_norm(v3_add(v3_scale(x, st), v3_scale(bs->ng, ct)));
	v3_basis(f.n, &f.t, &f.b);
#ifndef AJAR_NO_ANISOTROPY
	if (BSDF_IS_ANISO(bs)) { /* the anisotropy direction, turned with the normal */
		V3 t = v3_madd(bs->t, f.n, -v3_dot(bs->t, f.n));
		float lt = v3_len2(t);
		if (lt > 1e-12f) {
			f.t = v3_scale(t, 1.0f / sqrt(lt));
			f.b = v3_cross(f.n, f.t);
		}
	}
#endif
	return f;
}

/* Local coordinates of w in frame fr flipped by `side` (+-1). */
INLINE V3 bsdf_local(const BsdfFrame *fr, V3 w, float side)
{
	return v3(v3_dot(w, fr->t), v3_dot(w, fr->b), side * v3_dot(w, fr->n));
}

INLINE V3 bsdf_world(const BsdfFrame *fr, V3 w, float side)
{
	return v3_from_local(v3(w.x, w.y, side * w.z), fr->t, fr->b, fr->n);
}

/* |wl . m| / |wl . n| for the light-side direction wl (see bsdf.h's top): what
 * f is multiplied by where the normal m is bent; 0 where wl lies in n's
 * plane (the integrators' cosine is 0 there). */
INLINE float bsdf_bend_ratio(const Bsdf *bs, V3 m, V3 wl)
{
	float d = fabs(v3_dot(wl, bs->n));
	return d > 1e-7f ? fabs(v3_dot(wl, m)) / d : 0.0f;
}

/* Relative ior eta_t / eta_i for light leaving toward the side `side` of ng. */
INLINE float bsdf_eta(const Bsdf *bs, float side) { return side > 0.0f ? bs->ior : 1.0f / bs->ior; }

#endif
