/* test_device_cdf.c — sample_cdf as the device compiles it returns the very
 * bucket, probability and remapped number the host's binary search does.
 * On a CPU with AVX the device counts the last 16 entries in one vector
 * compare (kernels/sample/sampling.h), which equals the search only where
 * the table is nondecreasing, as every table the host builds is: tables of
 * every length around the vector's 16, with runs of equal entries
 * (zero-width buckets), a table whose first bucket is empty and one empty
 * throughout, probed at random numbers and at and beside every entry. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "device/device_build.h"
#include "device/kernel_source.h"
#include "sample/sampling.h"
#include "testutil.h"

#define PROBES_MAX 8192

/* A nondecreasing table of n + 1 entries from 0 to 1 whose buckets are
 * empty with probability `empty`. */
static void table(float *cdf, int n, double empty, unsigned *seed)
{
	double sum = 0.0, *w = malloc(sizeof *w * (size_t)n);
	for (int i = 0; i < n; i++) {
		*seed = *seed * 1664525u + 1013904223u;
		double r = (double)(*seed >> 8) / 16777216.0;
		w[i] = r < empty ? 0.0 : r;
		sum += w[i];
	}
	cdf[0] = 0.0f;
	double run = 0.0;
	for (int i = 0; i < n; i++) {
		run += w[i];
		cdf[i + 1] = sum > 0.0 ? (float)(run / sum) : 0.0f;
	}
	if (sum > 0.0)
		cdf[n] = 1.0f;
	free(w);
}

/* Numbers that probe every entry: the entry, its neighbours in float, and
 * random ones, plus the ends and beyond. */
static int probes(const float *cdf, int n, float *u, unsigned *seed)
{
	int m = 0;
	const float ends[] = {0.0f, -0.25f, 1.0f, 0.99999994f, 1.5f, 1e-30f};
	for (size_t i = 0; i < sizeof ends / sizeof ends[0]; i++)
		u[m++] = ends[i];
	for (int i = 0; i <= n && m + 3 <= PROBES_MAX / 2; i++) {
		u[m++] = cdf[i];
		u[m++] = nextafterf(cdf[i], 0.0f);
		u[m++] = nextafterf(cdf[i], 2.0f);
	}
	while (m < PROBES_MAX) {
		*seed = *seed * 1664525u + 1013904223u;
		u[m++] = (float)(*seed >> 8) / 16777216.0f;
	}
	return m;
}

static void test_device_equals_host(void **state)
{
	Device d;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t ndev;
	cl_kernel k;
	if (device_select(NULL, &plat, &id, 1, &ndev) != AJAR_OK || device_open(&d, plat, id) != AJAR_OK ||
	    device_build(&d, ajar_kernel_source, KERNEL_OPTIONS "0") != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(device_kernel(&d, "cdf_probe", &k), AJAR_OK);
	const int lengths[] = {1, 2, 3, 14, 15, 16, 17, 18, 30, 31, 32, 33, 47, 48, 49, 64, 100, 255, 256, 257, 512, 1024, 1025};
	const double empties[] = {0.0, 0.3, 0.9};
	float *cdf = malloc(sizeof *cdf * 1026), *u = malloc(sizeof *u * PROBES_MAX);
	float *dev = malloc(sizeof *dev * 3 * PROBES_MAX);
	unsigned seed = 7;
	int checked = 0, moved = 0;
	for (size_t li = 0; li < sizeof lengths / sizeof lengths[0]; li++)
		for (size_t ei = 0; ei < sizeof empties / sizeof empties[0] + 2; ei++) {
			int n = lengths[li];
			if (ei < 3) {
				table(cdf, n, empties[ei], &seed);
			} else if (ei == 3) { /* the first buckets empty: a run of zeros */
				table(cdf, n, 0.0, &seed);
				for (int i = 1; i <= n / 2 && i < n; i++)
					cdf[i] = 0.0f;
			} else { /* empty throughout: -1 */
				memset(cdf, 0, sizeof *cdf * (size_t)(n + 1));
			}
			int m = probes(cdf, n, u, &seed);
			cl_mem bc, bu, bo;
			assert_int_equal(device_buffer(&d, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
						       sizeof *cdf * (size_t)(n + 1), cdf, &bc),
					 AJAR_OK);
			assert_int_equal(device_buffer(&d, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof *u * (size_t)m, u,
						       &bu),
					 AJAR_OK);
			assert_int_equal(device_buffer(&d, CL_MEM_WRITE_ONLY, sizeof *dev * 3 * (size_t)m, NULL, &bo),
					 AJAR_OK);
			cl_uint count = (cl_uint)m;
			assert_int_equal(clSetKernelArg(k, 0, sizeof bc, &bc), CL_SUCCESS);
			assert_int_equal(clSetKernelArg(k, 1, sizeof n, &n), CL_SUCCESS);
			assert_int_equal(clSetKernelArg(k, 2, sizeof bu, &bu), CL_SUCCESS);
			assert_int_equal(clSetKernelArg(k, 3, sizeof bo, &bo), CL_SUCCESS);
			assert_int_equal(clSetKernelArg(k, 4, sizeof count, &count), CL_SUCCESS);
			size_t global = (size_t)m;
			assert_int_equal(clEnqueueNDRangeKernel(d.queue, k, 1, NULL, &global, NULL, 0, NULL, NULL),
					 CL_SUCCESS);
			assert_int_equal(clEnqueueReadBuffer(d.queue, bo, CL_TRUE, 0, sizeof *dev * 3 * (size_t)m, dev, 0,
							     NULL, NULL),
					 CL_SUCCESS);
			for (int i = 0; i < m; i++) {
				float pdf, ur;
				int want = sample_cdf(cdf, n, u[i], &pdf, &ur);
				if ((int)dev[3 * i] != want || memcmp(&dev[3 * i + 1], &pdf, sizeof pdf) != 0 ||
				    memcmp(&dev[3 * i + 2], &ur, sizeof ur) != 0)
					fail_msg("n %d, table %zu, u %.9g: device bucket %d (p %.9g, u' %.9g), host %d "
						 "(p %.9g, u' %.9g)",
						 n, ei, (double)u[i], (int)dev[3 * i], (double)dev[3 * i + 1],
						 (double)dev[3 * i + 2], want, (double)pdf, (double)ur);
				checked++;
				moved += want > 0;
			}
			clReleaseMemObject(bc);
			clReleaseMemObject(bu);
			clReleaseMemObject(bo);
		}
	/* The probes reached past the first bucket, so the search was exercised. */
	assert_true(moved > checked / 4);
	clReleaseKernel(k);
	device_close(&d);
	free(cdf);
	free(u);
	free(dev);
}

int main(void)
{
	const struct CMUnitTest tests[] = {cmocka_unit_test(test_device_equals_host)};
	return cmocka_run_group_tests_name("device_cdf", tests, NULL, NULL);
}
