/* test_layout.c — the device compiler lays out every shared struct exactly
 * as the host does: a probe kernel reports sizes and offsets in the order
 * of kernels/base/layout.h, compared with the host's (src/device/layout_check.c). */
#include <stdlib.h>

#include "device/device_build.h"
#include "device/kernel_source.h"
#include "testutil.h"

extern const unsigned ajar_layout_host[];
extern const unsigned ajar_layout_count;

static void test_probe_matches_host(void **state)
{
	Device d;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t n;
	cl_kernel k;
	cl_mem buf;
	cl_uint *dev = calloc(ajar_layout_count, sizeof *dev);
	if (device_select(NULL, &plat, &id, 1, &n) != AJAR_OK || device_open(&d, plat, id) != AJAR_OK ||
	    device_build(&d, ajar_kernel_source, KERNEL_OPTIONS "0") != AJAR_OK)
		fail_msg("%s", ajar_last_error());
	assert_int_equal(device_kernel(&d, "layout_probe", &k), AJAR_OK);
	assert_int_equal(device_buffer(&d, CL_MEM_WRITE_ONLY, sizeof(cl_uint) * ajar_layout_count, NULL, &buf),
			 AJAR_OK);
	size_t one = 1;
	assert_int_equal(clSetKernelArg(k, 0, sizeof buf, &buf), CL_SUCCESS);
	assert_int_equal(clEnqueueNDRangeKernel(d.queue, k, 1, NULL, &one, &one, 0, NULL, NULL), CL_SUCCESS);
	assert_int_equal(clEnqueueReadBuffer(d.queue, buf, CL_TRUE, 0, sizeof(cl_uint) * ajar_layout_count, dev, 0,
					     NULL, NULL),
			 CL_SUCCESS);
	for (unsigned i = 0; i < ajar_layout_count; i++)
		if (dev[i] != ajar_layout_host[i])
			fail_msg("layout entry %u (kernels/base/layout.h order): device %u, host %u", i, dev[i],
				 ajar_layout_host[i]);
	clReleaseMemObject(buf);
	clReleaseKernel(k);
	device_close(&d);
	free(dev);
}

int main(void)
{
	const struct CMUnitTest tests[] = {cmocka_unit_test(test_probe_matches_host)};
	return cmocka_run_group_tests_name("layout", tests, NULL, NULL);
}
