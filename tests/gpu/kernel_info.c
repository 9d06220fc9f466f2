/* kernel_info [SELECTOR] [PIXELS] — for each integrator and subpath layout
 * on one device (default "gpu"): the options render_pass is built with
 * (device_render_options), the build time (from Ajar's cache when warm),
 * the private memory a work-item takes (CL_KERNEL_PRIVATE_MEM_SIZE) and the
 * plan for an image of PIXELS pixels (default 640 x 360): work-items a
 * pixel, a launch's most, scratch bytes (tests/gpu/run.sh). It also warms
 * Ajar's kernel cache for the renders that follow. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "device/device_build.h"
#include "device/device_plan.h"
#include "device/kernel_source.h"

int main(int argc, char **argv)
{
	const char *sel = argc > 1 ? argv[1] : "gpu";
	size_t npix = argc > 2 ? (size_t)strtoull(argv[2], NULL, 10) : 640 * 360;
	cl_platform_id plat;
	cl_device_id id;
	uint32_t n = 0;
	static const char *const names[] = {"pt", "bdpt", "portal"};
	if (device_select(sel, &plat, &id, 1, &n) != AJAR_OK) {
		fprintf(stderr, "kernel_info: %s\n", ajar_last_error());
		return 2;
	}
	printf("integrator\tlayout\tbuild_s\tprivate_bytes\tlanes\tlaunch_max\tscratch_MB\toptions\n");
	for (int integ = 0; integ < 3; integ++)
		for (int soa = 0; soa < 2; soa++) {
			Device d;
			DevicePlan p;
			cl_kernel k = NULL;
			char opts[512];
			cl_ulong priv = 0;
			if (integ == 0 && soa)
				continue;
			setenv("AJAR_SUBPATHS", soa ? "global" : "private", 1);
			if (device_open(&d, plat, id) != AJAR_OK || device_plan(&d, integ, npix, &p) != AJAR_OK) {
				printf("%s\t%s\tfailed: %s\n", names[integ], soa ? "global" : "private", ajar_last_error());
				device_close(&d);
				continue;
			}
			device_render_options(&d, integ, &p, getenv("AJAR_CL_OPTIONS"), opts, sizeof opts);
			if (device_build(&d, ajar_kernel_source, opts) != AJAR_OK ||
			    device_kernel(&d, "render_pass", &k) != AJAR_OK) {
				printf("%s\t%s\tbuild failed: %.300s\n", names[integ], soa ? "global" : "private",
				       ajar_last_error());
				device_close(&d);
				continue;
			}
			clGetKernelWorkGroupInfo(k, d.id, CL_KERNEL_PRIVATE_MEM_SIZE, sizeof priv, &priv, NULL);
			printf("%s\t%s\t%.1f%s\t%llu\t%u\t%zu\t%.0f\t%s\n", names[integ], soa ? "global" : "private",
			       d.build_seconds, d.from_cache ? " (cache)" : "", (unsigned long long)priv, p.lanes,
			       p.soa ? p.capacity : npix * p.lanes, p.scratch_bytes / 1048576.0, opts);
			fflush(stdout);
			clReleaseKernel(k);
			device_close(&d);
		}
	unsetenv("AJAR_SUBPATHS");
	return 0;
}
