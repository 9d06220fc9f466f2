/* batch_means.c — see batch_means.h. */
#include "batch_means.h"

#include <math.h>
#include <stdlib.h>

#include "testutil.h"

void batch_means(ajar_renderer *r, uint32_t w, uint32_t h, int batches, uint32_t seed0, Estimate *e)
{
	float *img = malloc(sizeof(float) * 4 * w * h);
	assert_non_null(img);
	double s1[3] = {0}, s2[3] = {0};
	for (int b = 0; b < batches; b++) {
		assert_int_equal(ajar_renderer_restart(r, seed0 + (uint32_t)b), AJAR_OK);
		if (ajar_renderer_render(r, NULL, NULL) != AJAR_OK)
			fail_msg("%s", ajar_last_error());
		assert_int_equal(ajar_renderer_image(r, img, NULL, NULL), AJAR_OK);
		for (int c = 0; c < 3; c++) {
			double m = 0;
			for (uint32_t i = 0; i < w * h; i++)
				m += img[4 * i + c];
			m /= w * h;
			s1[c] += m;
			s2[c] += m * m;
		}
	}
	for (int c = 0; c < 3; c++) {
		e->mean[c] = s1[c] / batches;
		e->se[c] = sqrt(fmax(0, (s2[c] - s1[c] * s1[c] / batches) / (batches - 1)) / batches);
	}
	free(img);
}

void estimates_agree(const char *what, const char *na, const Estimate *a, const char *nb, const Estimate *b)
{
	for (int c = 0; c < 3; c++) {
		double se = sqrt(a->se[c] * a->se[c] + b->se[c] * b->se[c]);
		double d = a->mean[c] - b->mean[c];
		double z = se > 0 ? d / se : (d == 0 ? 0 : INFINITY); /* noiseless: equal or not */
		print_message("%s, channel %d: %s %.5f +- %.5f vs %s %.5f +- %.5f (%+.1f se, se %.2f%% of the mean)\n",
			      what, c, na, a->mean[c], a->se[c], nb, b->mean[c], b->se[c], z,
			      100 * se / fmax(fabs(b->mean[c]), 1e-12));
		if (fabs(z) > 5)
			fail_msg("%s, channel %d: %s and %s differ by %.1f standard errors", what, c, na, nb, z);
	}
}
