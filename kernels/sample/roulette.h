/* roulette.h — Russian roulette, one rule for every walk.
 *
 * A walk that continues with throughput beta survives with probability
 * q = min(boost max(beta) / beta_ref, RR_MAX_SURVIVAL) and carries
 * beta / q on; any q in (0, 1] keeps the estimate unbiased, so the rule only
 * trades variance against time.
 *
 * beta_ref is what "a throughput that still matters" means for the walk.
 * For a camera walk it is the throughput after the first scattering, not 1:
 * a pixel's value already carries the albedo of the surface it sees, so on
 * a dark carpet (albedo 0.1) an absolute rule would end nine walks in ten at
 * the second bounce, and the pixel's indirect light, which is most of its
 * value, would rest on a tenth of the samples. Relative to the pixel, what
 * matters is the throughput since that first scattering (the idea behind
 * adjoint-driven Russian roulette, Vorba and Krivanek 2016, with the pixel's
 * albedo standing in for its estimate).
 *
 * The boost trades longer camera walks against their cost. Where an eye
 * vertex is cheap (pt; portal without light subpaths: a next-event sample
 * and the next ray) 2 does best: on living-room and window-room the
 * variance per sample fell 8% and 20% against 1.5 at about the same time.
 * Where every eye vertex also connects to each vertex of a light subpath
 * (bdpt; portal in scenes with emitters), 2 cost door-ajar's portal
 * integrator 10% in efficiency, and 1.5 leaves it and bathroom even
 * against the old absolute rule (kernels/sample/README.md, "Russian roulette"). */
#ifndef AJAR_ROULETTE_H
#define AJAR_ROULETTE_H
#include "sample/rng.h"
#include "base/vec.h"

#define RR_BOOST 2.0f           /* walks with cheap vertices */
#define RR_BOOST_CONNECTED 1.5f /* walks whose eye vertices connect to light subpaths */
#define RR_MAX_SURVIVAL 0.95f

/* Plays the roulette on *beta: 0 if the walk ends, else 1 with *beta
 * divided by the survival probability. */
INLINE int rr_survive(V3 *beta, float beta_ref, float boost, Rng *rng)
{
	float q = fmin(boost * v3_maxc(*beta) / beta_ref, RR_MAX_SURVIVAL);
	if (!(rng_f(rng) < q))
		return 0;
	*beta = v3_scale(*beta, 1.0f / q);
	return 1;
}

#endif
