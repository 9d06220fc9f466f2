/* device_select.c — the OpenCL devices there are (ajar_devices) and which
 * of them a selector list chooses. Everything here reads the platforms
 * afresh: the list is short and a driver may come or go between renders. */
#include "device/device_select.h"

#include <stdio.h>
#include <string.h>

#include "core/error.h"

#define MAX_PLATFORMS 16
#define MAX_DEVICES 64

/* All devices of all platforms; platforms without devices are skipped. */
static int enumerate(cl_platform_id *plat_of, cl_device_id *ids, int *pidx, int *didx, int cap)
{
	cl_platform_id plats[MAX_PLATFORMS];
	cl_uint nplat = 0;
	int n = 0;
	if (clGetPlatformIDs(MAX_PLATFORMS, plats, &nplat) != CL_SUCCESS)
		return 0;
	for (cl_uint p = 0; p < nplat && p < MAX_PLATFORMS; p++) {
		cl_device_id devs[MAX_DEVICES];
		cl_uint ndev = 0;
		if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, MAX_DEVICES, devs, &ndev) != CL_SUCCESS)
			continue;
		for (cl_uint i = 0; i < ndev && i < MAX_DEVICES && n < cap; i++, n++) {
			plat_of[n] = plats[p];
			ids[n] = devs[i];
			pidx[n] = (int)p;
			didx[n] = (int)i;
		}
	}
	return n;
}

static const char *type_name(cl_device_type t)
{
	if (t & CL_DEVICE_TYPE_GPU)
		return "gpu";
	if (t & CL_DEVICE_TYPE_CPU)
		return "cpu";
	if (t & CL_DEVICE_TYPE_ACCELERATOR)
		return "accelerator";
	return "other";
}

ajar_status device_list(ajar_device_info *out, uint32_t capacity, uint32_t *count)
{
	cl_platform_id plats[MAX_DEVICES];
	cl_device_id ids[MAX_DEVICES];
	int pidx[MAX_DEVICES], didx[MAX_DEVICES];
	int n = enumerate(plats, ids, pidx, didx, MAX_DEVICES);
	if (!count)
		return err_set(AJAR_ERROR_INVALID_ARGUMENT, "ajar_devices: count is NULL");
	*count = (uint32_t)n;
	for (int i = 0; i < n && (uint32_t)i < capacity && out; i++) {
		ajar_device_info *o = &out[i];
		cl_device_type t = 0;
		cl_uint cu = 0;
		cl_ulong mem = 0;
		memset(o, 0, sizeof *o);
		snprintf(o->selector, sizeof o->selector, "%d:%d", pidx[i], didx[i]);
		clGetPlatformInfo(plats[i], CL_PLATFORM_NAME, sizeof o->platform - 1, o->platform, NULL);
		clGetDeviceInfo(ids[i], CL_DEVICE_NAME, sizeof o->name - 1, o->name, NULL);
		clGetDeviceInfo(ids[i], CL_DEVICE_TYPE, sizeof t, &t, NULL);
		clGetDeviceInfo(ids[i], CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cu, &cu, NULL);
		clGetDeviceInfo(ids[i], CL_DEVICE_GLOBAL_MEM_SIZE, sizeof mem, &mem, NULL);
		snprintf(o->type, sizeof o->type, "%s", type_name(t));
		o->compute_units = cu;
		o->global_memory = mem;
	}
	return AJAR_OK;
}

static int contains_ci(const char *hay, const char *needle)
{
	size_t n = strlen(needle);
	for (; *hay; hay++) {
		size_t i = 0;
		while (i < n && hay[i] && (hay[i] | 32) == (needle[i] | 32))
			i++;
		if (i == n)
			return 1;
	}
	return 0;
}

/* Does device i (of the enumeration) match one selector item? */
static int item_matches(const char *item, int i, cl_device_id id, const int *pidx, const int *didx)
{
	cl_device_type t = 0;
	char name[256] = "";
	int p, d;
	char end;
	clGetDeviceInfo(id, CL_DEVICE_TYPE, sizeof t, &t, NULL);
	clGetDeviceInfo(id, CL_DEVICE_NAME, sizeof name - 1, name, NULL);
	if (sscanf(item, "%d:%d%c", &p, &d, &end) == 2)
		return p == pidx[i] && d == didx[i];
	if (sscanf(item, "%d%c", &p, &end) == 1)
		return p == i;
	if (!strcmp(item, "cpu"))
		return (t & CL_DEVICE_TYPE_CPU) != 0;
	if (!strcmp(item, "gpu"))
		return (t & CL_DEVICE_TYPE_GPU) != 0;
	return contains_ci(name, item);
}

ajar_status device_select(const char *sel, cl_platform_id *platforms, cl_device_id *out, uint32_t cap,
			  uint32_t *count)
{
	cl_platform_id plats[MAX_DEVICES];
	cl_device_id ids[MAX_DEVICES];
	int pidx[MAX_DEVICES], didx[MAX_DEVICES], taken[MAX_DEVICES] = {0};
	int n = enumerate(plats, ids, pidx, didx, MAX_DEVICES);
	uint32_t k = 0;
	*count = 0;
	if (n == 0)
		return err_set(AJAR_ERROR_DEVICE,
			       "no OpenCL device found: is an ICD installed (e.g. pocl-opencl-icd) and "
			       "/etc/OpenCL/vendors readable?");
	if (!sel || !sel[0]) { /* the first CPU device, else the first of any kind */
		int pick = 0;
		for (int i = n - 1; i >= 0; i--)
			pick = item_matches("cpu", i, ids[i], pidx, didx) ? i : pick;
		platforms[0] = plats[pick];
		out[0] = ids[pick];
		*count = 1;
		return AJAR_OK;
	}
	/* A comma-separated list: each item takes its first match not taken
	 * by an earlier item ("cpu,cpu" is two CPU devices), "all" takes every
	 * device not taken yet. */
	for (const char *p = sel; *p && k < cap;) {
		char item[128];
		size_t len = strcspn(p, ",");
		const char *next = p[len] ? p + len + 1 : p + len;
		while (len > 0 && (*p == ' ' || *p == '\t')) {
			p++;
			len--;
		}
		while (len > 0 && (p[len - 1] == ' ' || p[len - 1] == '\t'))
			len--;
		if (len == 0 || len >= sizeof item)
			return err_set(AJAR_ERROR_INVALID_ARGUMENT,
				       "device list '%s': empty or overlong item (see `ajar devices`)", sel);
		memcpy(item, p, len);
		item[len] = '\0';
		int all = !strcmp(item, "all"), found = 0, twice = 0;
		for (int i = 0; i < n && k < cap; i++) {
			if (!(all || item_matches(item, i, ids[i], pidx, didx)))
				continue;
			twice |= taken[i];
			if (taken[i])
				continue;
			taken[i] = found = 1;
			platforms[k] = plats[i];
			out[k++] = ids[i];
			if (!all)
				break;
		}
		if (!found && !all && twice)
			return err_set(AJAR_ERROR_DEVICE, "device list '%s': '%s' is listed twice", sel, item);
		if (!found && !all)
			return err_set(AJAR_ERROR_DEVICE, "no OpenCL device matches '%s'%s%s%s (see `ajar devices`)", item,
				       strchr(sel, ',') ? " in the list '" : "", strchr(sel, ',') ? sel : "",
				       strchr(sel, ',') ? "'" : "");
		p = next;
	}
	*count = k;
	return AJAR_OK;
}

void device_selector_of(cl_device_id id, char *buf, size_t cap)
{
	cl_platform_id plats[MAX_DEVICES];
	cl_device_id ids[MAX_DEVICES];
	int pidx[MAX_DEVICES], didx[MAX_DEVICES];
	int n = enumerate(plats, ids, pidx, didx, MAX_DEVICES);
	snprintf(buf, cap, "?");
	for (int i = 0; i < n; i++)
		if (ids[i] == id)
			snprintf(buf, cap, "%d:%d", pidx[i], didx[i]);
}
