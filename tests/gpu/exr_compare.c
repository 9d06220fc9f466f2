/* exr_compare A.exr B.exr [TOL] — how closely a GPU render matches PoCL's
 * of the same scene, seed and options (tests/gpu/run.sh): the mean of each
 * image, their relative difference, the share of pixels equal bit for bit
 * and the largest pixel difference. Exits 1 when the means differ by more
 * than TOL relative (default 3e-5, what kernels/README.md, "On GPUs" states
 * for the H100 against PoCL), 2 on bad input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ajar.h"

int main(int argc, char **argv)
{
	float *a = NULL, *b = NULL;
	uint32_t wa, ha, wb, hb;
	if (argc < 3 || argc > 4) {
		fprintf(stderr, "usage: exr_compare A.exr B.exr [TOL]\n");
		return 2;
	}
	double tol = argc == 4 ? atof(argv[3]) : 3e-5;
	if (ajar_read_exr(argv[1], &a, &wa, &ha) != AJAR_OK || ajar_read_exr(argv[2], &b, &wb, &hb) != AJAR_OK) {
		fprintf(stderr, "exr_compare: %s\n", ajar_last_error());
		return 2;
	}
	if (wa != wb || ha != hb) {
		fprintf(stderr, "exr_compare: %s is %ux%u, %s %ux%u\n", argv[1], wa, ha, argv[2], wb, hb);
		return 2;
	}
	size_t n = (size_t)wa * ha, same = 0;
	double ma = 0, mb = 0, dmax = 0;
	for (size_t i = 0; i < n; i++) {
		same += memcmp(&a[4 * i], &b[4 * i], 3 * sizeof(float)) == 0;
		for (int c = 0; c < 3; c++) {
			ma += a[4 * i + c];
			mb += b[4 * i + c];
			dmax = fmax(dmax, fabs((double)a[4 * i + c] - b[4 * i + c]));
		}
	}
	ma /= 3.0 * n;
	mb /= 3.0 * n;
	double rel = ma != 0 ? fabs(mb - ma) / fabs(ma) : fabs(mb);
	printf("mean %.7g vs %.7g  rel %.2e  pixels equal %.2f%%  max diff %.3g  %s\n", ma, mb, rel,
	       100.0 * same / n, dmax, rel <= tol ? "ok" : "DIFFERS");
	free(a);
	free(b);
	return rel <= tol ? 0 : 1;
}
