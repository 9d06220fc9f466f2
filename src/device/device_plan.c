/* device_plan.c — how a pass spreads over a device (DevicePlan): where
 * bdpt's and portal's subpaths live, how many work-items a pixel gets, and
 * the options render_pass is built with for that plan and the scene's
 * features (kernels/integrator/README.md, "Where subpaths live"). */
#include "device/device_plan.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/env_vars.h"
#include "core/error.h"
#include "device/device_build.h"
#include "light/portal_sky.h"
#include "prepare/prepare.h"
#include "base/types.h"

/* A positive integer from the environment: *out, 1 if set, -1 if malformed. */
static int env_count(EnvVar name, unsigned long long *out)
{
	const char *v = env_var(name);
	char *end;
	if (!v || !v[0])
		return 0;
	errno = 0;
	unsigned long long n = strtoull(v, &end, 10);
	if (errno || *end || n == 0 || v[0] == '-')
		return -1;
	*out = n;
	return 1;
}

ajar_status device_plan(const Device *d, int integrator, size_t npix, DevicePlan *p)
{
	cl_uint cu = 1;
	size_t max_wg = 1;
	cl_ulong mem = 0, max_alloc = 0;
	unsigned long long v;
	int got;
	memset(p, 0, sizeof *p);
	clGetDeviceInfo(d->id, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
	clGetDeviceInfo(d->id, CL_DEVICE_MAX_WORK_GROUP_SIZE, sizeof max_wg, &max_wg, NULL);
	clGetDeviceInfo(d->id, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof mem, &mem, NULL);
	clGetDeviceInfo(d->id, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc, &max_alloc, NULL);
	if (cu < 1)
		cu = 1;
	if (max_wg < 1)
		max_wg = 1;
	/* Work-items in flight that keep the device busy: a GPU's compute
	 * units each hold about two work-groups of the largest size (an H100
	 * SM: 2048 threads); a CPU's, one pixel at a time each. */
	size_t flight = d->is_cpu ? 256 * (size_t)cu : 2 * (size_t)cu * max_wg;
	const char *mode = env_var(ENV_VAR_SUBPATHS);
	int bidirectional = integrator != INTEGRATOR_PT;
	if (mode && mode[0] && strcmp(mode, "private") && strcmp(mode, "global"))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "AJAR_SUBPATHS='%s': expected private or global", mode);
	p->soa = bidirectional && (mode && mode[0] ? !strcmp(mode, "global") : !d->is_cpu);
	p->lanes = 1;
	if (!d->is_cpu && npix > 0 && npix < flight)
		p->lanes = (unsigned)((flight + npix - 1) / npix);
	if ((got = env_count(ENV_VAR_PASS_LANES, &v)) < 0 || (got && v > 1024))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "AJAR_PASS_LANES='%s': expected 1 to 1024",
			       env_var(ENV_VAR_PASS_LANES));
	if (got)
		p->lanes = (unsigned)v;
	else if (p->lanes > 64)
		p->lanes = 64;
	while (p->lanes > 1 && (unsigned long long)npix * p->lanes >= 1ull << 31)
		p->lanes--;
	const char *feat = env_var(ENV_VAR_KERNEL_FEATURES);
	if (feat && feat[0] && strcmp(feat, "all") && strcmp(feat, "scene"))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "AJAR_KERNEL_FEATURES='%s': expected all or scene", feat);
	p->general = feat && !strcmp(feat, "all");
	if ((got = env_count(ENV_VAR_SUBPATH_CAPACITY, &v)) < 0 || (got && v > (1ull << 31)))
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "AJAR_SUBPATH_CAPACITY='%s': expected a work-item count",
			       env_var(ENV_VAR_SUBPATH_CAPACITY));
	if (!p->soa)
		return AJAR_OK;
	/* The slots of kernels/ajar.cl: light, eye and its next-event vertex, the two halves (portal). */
	size_t item = (size_t)(integrator == INTEGRATOR_PORTAL ? 4 * DEVICE_SUBPATH_MAX + 1 : 2 * DEVICE_SUBPATH_MAX + 1) *
		      DEVICE_VERTEX_WORDS * 4;
	cl_ulong budget = mem / 2 < max_alloc || !max_alloc ? mem / 2 : max_alloc;
	size_t cap = (flight + 63) / 64 * 64;
	if (got)
		cap = (size_t)v;
	else if (budget > 0 && cap * (cl_ulong)item > budget)
		cap = (size_t)(budget / item) / 64 * 64;
	if (cap == 0 || (budget > 0 && cap * (cl_ulong)item > budget))
		return err_set(AJAR_ERROR_OUT_OF_MEMORY,
			       "device %s: no room for the subpath scratch (%zu bytes a work-item, %llu bytes of memory)",
			       d->name, item, (unsigned long long)mem);
	p->capacity = cap;
	p->scratch_bytes = cap * item;
	return AJAR_OK;
}

void device_render_options(const Device *d, int integrator, const DevicePlan *p, const char *extra, char *buf,
			   size_t cap)
{
	static const struct {
		unsigned bit;
		const char *option;
	} omit[] = {{KERNEL_OMIT_ALPHA, "-DAJAR_NO_ALPHA "},
		    {KERNEL_OMIT_BENT_NORMALS, "-DAJAR_NO_BENT_NORMALS "},
		    {KERNEL_OMIT_TEXTURES, "-DAJAR_NO_TEXTURES "},
		    {KERNEL_OMIT_TRI_EXTRA, "-DAJAR_NO_TRI_EXTRA "},
		    {KERNEL_OMIT_PANES, "-DAJAR_NO_PANES "},
		    {KERNEL_OMIT_INSTANCES, "-DAJAR_NO_INSTANCES "},
		    {KERNEL_OMIT_LAYERS, "-DAJAR_NO_LAYERS "},
		    {KERNEL_OMIT_ANISOTROPY, "-DAJAR_NO_ANISOTROPY "}};
	device_build_options(d, integrator, NULL, buf, cap);
	size_t n = strlen(buf);
	if (p->soa)
		n += (size_t)snprintf(buf + n, cap - n, "-DAJAR_SUBPATH_SOA=%zu -DAJAR_SUBPATH_WORDS=%d ", p->capacity,
				      DEVICE_VERTEX_WORDS);
	for (size_t i = 0; i < sizeof omit / sizeof omit[0] && n < cap; i++)
		if (!p->general && (p->omit & omit[i].bit))
			n += (size_t)snprintf(buf + n, cap - n, "%s", omit[i].option);
	if (p->sky_res && p->sky_res != PORTAL_SKY_RES && n < cap)
		n += (size_t)snprintf(buf + n, cap - n, "-DPORTAL_SKY_RES=%d ", p->sky_res);
	if (n < cap)
		snprintf(buf + n, cap - n, "%s", extra ? extra : "");
}
