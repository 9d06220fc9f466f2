/* qmc.h — the low-discrepancy part of a pixel sample's random numbers.
 *
 * Dimensions are taken in pairs; each pair is the Sobol (0,2)-sequence
 * (its first two dimensions: van der Corput and the one with direction
 * numbers v_{k+1} = v_k ^ (v_k >> 1)), made random and independent of the
 * other pairs and pixels as Burley does it ("Practical hash-based Owen
 * scrambling", JCGT 2020):
 *  - the sample index is shuffled by a nested uniform scramble seeded per
 *    pixel and pair, a permutation under which the first 2^k samples of a
 *    pixel still form a (0,k,2)-net of the pair (their low k index bits stay
 *    distinct, and those alone fix the first k bits of both coordinates);
 *  - each coordinate is Owen-scrambled with its own seed, which keeps that
 *    net and makes every single point uniform in [0,1)^2.
 * Every sample is therefore uniform (estimates stay unbiased), while the
 * samples of one pixel fill each pair's square far more evenly than
 * independent ones, which is where most of a pixel's variance at hundreds of
 * samples comes from: pixel position, the first scattering and next-event
 * directions (README, Sampling). */
#ifndef AJAR_QMC_H
#define AJAR_QMC_H
#include "compat.h"

INLINE uint qmc_reverse_bits(uint x)
{
	x = (x << 16) | (x >> 16);
	x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
	x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
	x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
	return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}

/* 32-bit integer hash (Wellons' lowbias32): seeds from seeds. */
INLINE uint qmc_hash(uint x)
{
	x ^= x >> 16;
	x *= 0x7feb352du;
	x ^= x >> 15;
	x *= 0x846ca68bu;
	return x ^ (x >> 16);
}

/* Owen scrambling of x read as a binary fraction (most significant bit
 * first): every bit is flipped by a hash of the bits above it. In reversed
 * order that is Laine and Karras' permutation, where each step only carries
 * bits upward (Burley's constants). */
INLINE uint qmc_owen(uint x, uint seed)
{
	x = qmc_reverse_bits(x);
	x += seed;
	x ^= x * 0x6c50b47cu;
	x ^= x * 0xb82f1e52u;
	x ^= x * 0xc7afe638u;
	x ^= x * 0x8d22f6e6u;
	return qmc_reverse_bits(x);
}

/* Second Sobol dimension of point i, as a 32-bit binary fraction
 * (branch-free: one step per bit of i). */
INLINE uint qmc_sobol1(uint i)
{
	uint r = 0u;
	for (uint v = 0x80000000u; i != 0u; i >>= 1, v ^= v >> 1)
		r ^= v & (0u - (i & 1u));
	return r;
}

INLINE float qmc_to_float(uint x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* The pair's seed, and sample `index` shuffled for it. */
INLINE uint qmc_pair_index(uint index, uint pair, uint seed, uint *pair_seed)
{
	*pair_seed = qmc_hash(seed ^ qmc_hash(pair + 0x9e3779b9u));
	return qmc_owen(index, *pair_seed);
}

/* Both coordinates of pair `pair` of sample `index` of the pixel whose seed
 * is `seed`, in [0, 1) with 24 bits (exact in a float, never 1). */
INLINE void qmc_pair(uint index, uint pair, uint seed, float *x, float *y)
{
	uint ps, i = qmc_pair_index(index, pair, seed, &ps);
	*x = qmc_to_float(qmc_owen(qmc_reverse_bits(i), qmc_hash(ps + 1u)));
	*y = qmc_to_float(qmc_owen(qmc_sobol1(i), qmc_hash(ps + 2u)));
}

/* Dimension `dim` alone: coordinate dim & 1 of pair dim >> 1. */
INLINE float qmc_f(uint index, uint dim, uint seed)
{
	uint ps, i = qmc_pair_index(index, dim >> 1, seed, &ps);
	uint x = (dim & 1u) ? qmc_sobol1(i) : qmc_reverse_bits(i);
	return qmc_to_float(qmc_owen(x, qmc_hash(ps + 1u + (dim & 1u))));
}

#endif
