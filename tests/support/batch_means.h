/* batch_means.h — the device tests' estimate of an image's mean: the
 * means of several renders at new seeds, and whether two such estimates
 * agree (test_integrators, test_found_portals, test_glass). */
#ifndef AJAR_TEST_BATCH_MEANS_H
#define AJAR_TEST_BATCH_MEANS_H
#include <stdint.h>

#include "ajar.h"

typedef struct {
	double mean[3], se[3];
} Estimate;

/* r (w x h) rendered `batches` times, restarted at seeds seed0, seed0 + 1,
 * ...: per channel, the mean of the image means and its standard error. */
void batch_means(ajar_renderer *r, uint32_t w, uint32_t h, int batches, uint32_t seed0, Estimate *e);
/* z of a - b per channel in combined standard errors (printed with `what`,
 * names na and nb); fails the test beyond 5. */
void estimates_agree(const char *what, const char *na, const Estimate *a, const char *nb, const Estimate *b);

#endif
