/* rng.h — the random number stream of one pixel sample.
 *
 * Counter-based seeding: (seed, pixel, sample index, stream) is hashed with
 * the splitmix64 finaliser into the state and the stream selector of a PCG32
 * generator (O'Neill 2014, XSH-RR output). The hash makes neighbouring
 * pixels and samples independent streams, and the same four numbers give the
 * same sequence on every device and on the host, so renders are repeatable
 * bit for bit and several devices can render disjoint samples.
 *
 * A pixel sample (rng_init_pixel) also draws low-discrepancy numbers
 * (qmc.h), indexed by the sample's number within its pixel, for the
 * decisions that matter most, in two sequences so the order in which an
 * integrator makes its decisions does not matter: the main one (rng_pixel,
 * rng_f3: the pixel position, then the camera walk's scattering) and the
 * next-event one (rng_nee3: light samples along the camera walk), each for
 * its first RNG_QMC_DIMS numbers. Everything else (light subpaths and
 * intermediate subpaths on a stream of their own, rng_fork; the film's
 * stochastic rounding, rng_pcg_f) and what follows those numbers is PCG32. */
#ifndef AJAR_RNG_H
#define AJAR_RNG_H
#include "base/compat.h"
#include "sample/qmc.h"

/* Low-discrepancy numbers per sequence: in the main one the pixel
 * position and five scattering directions, in the next-event one three
 * light samples (a pair for the point or direction, and the first number
 * of another for the choice of light). */
#define RNG_QMC_DIMS 12u

/* Floats of a sample's low-discrepancy numbers, both sequences: its
 * 2 RNG_QMC_DIMS / 2 pairs, made ahead by rng_qmc_table. */
#define RNG_QMC_FLOATS (2u * RNG_QMC_DIMS)

typedef struct {
	ulong state;
	ulong inc;              /* odd: selects one of 2^63 PCG streams */
	const float *qmc;       /* the sample's low-discrepancy numbers (rng_qmc_table); unread by PCG-only streams */
	uint dim;               /* main sequence: numbers drawn; PCG's from RNG_QMC_DIMS on */
	uint nee_dim;           /* next-event sequence: the same */
} Rng;

/* splitmix64's output function: a bijective 64-bit mixer with full
 * avalanche, so nearby inputs give unrelated outputs. */
INLINE ulong rng_mix64(ulong z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9UL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebUL;
	return z ^ (z >> 31);
}

INLINE uint rng_u32(Rng *r)
{
	ulong old = r->state;
	r->state = old * 6364136223846793005UL + r->inc;
	uint xorshifted = (uint)(((old >> 18) ^ old) >> 27);
	uint rot = (uint)(old >> 59);
	return (xorshifted >> rot) | (xorshifted << ((0u - rot) & 31u));
}

INLINE Rng rng_init(uint seed, uint pixel, uint sample_index, uint stream)
{
	/* Two chained hashes so that every input bit reaches every output bit;
	 * the golden-ratio offsets keep all-zero inputs away from the fixed
	 * point 0 of the mixer. */
	ulong a = rng_mix64((((ulong)seed << 32) | (ulong)pixel) + 0x9e3779b97f4a7c15UL);
	ulong b = rng_mix64(a ^ ((((ulong)sample_index << 32) | (ulong)stream) + 0x6a09e667f3bcc909UL));
	Rng r;
	r.qmc = 0;
	r.dim = r.nee_dim = RNG_QMC_DIMS; /* PCG only */
	r.state = 0UL;
	r.inc = (rng_mix64(b + 0x9e3779b97f4a7c15UL) << 1) | 1UL;
	/* PCG's seeding sequence: step, add the initial state, step. */
	rng_u32(&r);
	r.state += b;
	rng_u32(&r);
	return r;
}

/* The low-discrepancy numbers' scrambling seed of `pixel`. */
INLINE uint rng_qmc_seed(uint seed, uint pixel)
{
	return (uint)rng_mix64((((ulong)seed << 32) | (ulong)pixel) + 0x3c6ef372fe94f82bUL);
}

/* The low-discrepancy numbers of sample `index` of `pixel` into q: pair p
 * of the sequences (the main one's pairs 0 to RNG_QMC_DIMS / 2 - 1, then
 * the next-event one's) at q[2p] and q[2p + 1]. Made all at once before the
 * walk, on the device in the 16 lanes of qmc_pairs16: PoCL runs the walk
 * one work-item at a time, and inside it each pair was made alone, a
 * tenth of a Cornell `pt` sample (kernels/README.md, "By part, on PoCL"). */
INLINE void rng_qmc_table(uint seed, uint pixel, uint index, float q[RNG_QMC_FLOATS])
{
	uint qseed = rng_qmc_seed(seed, pixel);
#ifdef AJAR_DEVICE
	float16 x, y;
	qmc_pairs16(index, qseed, &x, &y);
	float xs[16], ys[16];
	vstore16(x, 0, xs);
	vstore16(y, 0, ys);
	for (uint p = 0u; p < RNG_QMC_DIMS; p++) {
		q[2u * p] = xs[p];
		q[2u * p + 1u] = ys[p];
	}
#else
	for (uint p = 0u; p < RNG_QMC_DIMS; p++)
		qmc_pair(index, p, qseed, &q[2u * p], &q[2u * p + 1u]);
#endif
}

/* The stream of sample `sample_index` of `pixel`: its first RNG_QMC_DIMS
 * numbers of each sequence low-discrepancy across the pixel's samples
 * (qmc.h), read from q, which rng_qmc_table filled for the same seed,
 * pixel and sample (q must outlive the stream); the rest as rng_init's stream 0. */
INLINE Rng rng_init_pixel(uint seed, uint pixel, uint sample_index, const float q[RNG_QMC_FLOATS])
{
	Rng r = rng_init(seed, pixel, sample_index, 0u);
	r.qmc = q;
	r.dim = r.nee_dim = 0u;
	return r;
}

/* Uniform in [0, 1) from PCG alone: the top 24 bits are exact in a float,
 * so the largest value is 1 - 2^-24 and never rounds up to 1. */
INLINE float rng_pcg_f(Rng *r) { return (float)(rng_u32(r) >> 8) * (1.0f / 16777216.0f); }

/* Uniform in [0, 1), for decisions of one number (Russian roulette, a
 * BSDF's lobe, subpaths' own streams): PCG, which leaves the
 * low-discrepancy numbers to the 2D decisions that gain the most. */
INLINE float rng_f(Rng *r) { return rng_pcg_f(r); }

/* The next pair of the sequence whose count is *dim (the main one at base
 * 0, the next-event one at base RNG_QMC_DIMS), or PCG once it is used up. */
INLINE void rng_pair(Rng *r, uint *dim, uint base, float *u1, float *u2)
{
	if (*dim + 2u > RNG_QMC_DIMS) {
		*u1 = rng_pcg_f(r);
		*u2 = rng_pcg_f(r);
		return;
	}
	uint k = base + *dim; /* pair k / 2's first coordinate */
	*u1 = r->qmc[k];
	*u2 = r->qmc[k + 1u];
	*dim += 2u;
}

/* The position within the pixel: the main sequence's first pair. */
INLINE void rng_pixel(Rng *r, float *jx, float *jy) { rng_pair(r, &r->dim, 0u, jx, jy); }

/* Three PCG numbers in the order of the arguments: a decision whose
 * sequence is used up draws them as streams without one always did. */
INLINE void rng_pcg3(Rng *r, float *u0, float *u1, float *u2)
{
	*u0 = rng_pcg_f(r);
	*u1 = rng_pcg_f(r);
	*u2 = rng_pcg_f(r);
}

/* A scattering decision: *u0 picks the lobe (PCG), *u1 and *u2 the
 * direction (the main sequence's next pair). */
INLINE void rng_f3(Rng *r, float *u0, float *u1, float *u2)
{
	if (r->dim + 2u > RNG_QMC_DIMS) {
		rng_pcg3(r, u0, u1, u2);
		return;
	}
	rng_pair(r, &r->dim, 0u, u1, u2);
	*u0 = rng_pcg_f(r);
}

/* A next-event decision: *u1 and *u2 the point or direction on the light
 * (the next-event sequence's next pair), *u0 the light (the first number
 * of the pair after it). */
INLINE void rng_nee3(Rng *r, float *u0, float *u1, float *u2)
{
	if (r->nee_dim + 2u > RNG_QMC_DIMS) {
		rng_pcg3(r, u0, u1, u2);
		return;
	}
	rng_pair(r, &r->nee_dim, RNG_QMC_DIMS, u1, u2);
	if (r->nee_dim + 2u > RNG_QMC_DIMS) {
		*u0 = rng_pcg_f(r);
		return;
	}
	*u0 = r->qmc[RNG_QMC_DIMS + r->nee_dim];
	r->nee_dim += 2u;
}

/* A PCG-only stream of its own, seeded from r's: for subpaths whose
 * numbers must not take r's low-discrepancy ones. */
INLINE Rng rng_fork(Rng *r)
{
	uint a = rng_u32(r), b = rng_u32(r);
	return rng_init(a, b, 0x85ebca6bu, 0xc2b2ae35u);
}

#endif
