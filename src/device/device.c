/* device.c — OpenCL discovery, selection, program build and binary cache.
 *
 * Program binaries are cached per device and per hash of (source, options,
 * device name, driver and platform version), so the second run of the same
 * build skips the OpenCL C front end. Cache files are written to a temporary
 * name and renamed, so concurrent renders never read a half-written binary.
 * A file starts with a magic and a hash of the binary that follows: some
 * drivers (PoCL 3.1) crash on a damaged binary instead of rejecting it, so
 * a file that fails the check is never handed to the driver. */
#include "device/device.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/env_vars.h"
#include "core/error.h"
#include "device/kernel_source.h"
#include "light/portal_sky.h"
#include "base/types.h"

#define MAX_PLATFORMS 16
#define MAX_DEVICES 64

const char *cl_error_name(cl_int err)
{
	switch (err) {
#define E(x) case x: return #x;
	E(CL_DEVICE_NOT_FOUND) E(CL_DEVICE_NOT_AVAILABLE) E(CL_COMPILER_NOT_AVAILABLE)
	E(CL_MEM_OBJECT_ALLOCATION_FAILURE) E(CL_OUT_OF_RESOURCES) E(CL_OUT_OF_HOST_MEMORY)
	E(CL_BUILD_PROGRAM_FAILURE) E(CL_INVALID_VALUE) E(CL_INVALID_DEVICE) E(CL_INVALID_BINARY)
	E(CL_INVALID_BUILD_OPTIONS) E(CL_INVALID_PROGRAM) E(CL_INVALID_PROGRAM_EXECUTABLE)
	E(CL_INVALID_KERNEL_NAME) E(CL_INVALID_KERNEL_ARGS) E(CL_INVALID_ARG_INDEX)
	E(CL_INVALID_ARG_VALUE) E(CL_INVALID_ARG_SIZE) E(CL_INVALID_WORK_GROUP_SIZE)
	E(CL_INVALID_WORK_ITEM_SIZE) E(CL_INVALID_GLOBAL_WORK_SIZE) E(CL_INVALID_BUFFER_SIZE)
	E(CL_INVALID_MEM_OBJECT) E(CL_INVALID_COMMAND_QUEUE) E(CL_INVALID_CONTEXT)
	E(CL_INVALID_PLATFORM) E(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
	E(CL_INVALID_KERNEL) E(CL_INVALID_OPERATION)
#undef E
	}
	return "unknown OpenCL error";
}

ajar_status cl_fail(const Device *d, const char *what, cl_int err)
{
	ajar_status st = (err == CL_OUT_OF_HOST_MEMORY || err == CL_MEM_OBJECT_ALLOCATION_FAILURE)
				 ? AJAR_ERROR_OUT_OF_MEMORY
				 : AJAR_ERROR_DEVICE;
	return err_set(st, "OpenCL device %s: %s failed: %s (%d)", d && d->name[0] ? d->name : "?", what,
		       cl_error_name(err), (int)err);
}

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

ajar_status device_open(Device *d, cl_platform_id platform, cl_device_id id)
{
	cl_int err;
	cl_device_type t = 0;
	memset(d, 0, sizeof *d);
	d->platform = platform;
	d->id = id;
	clGetDeviceInfo(id, CL_DEVICE_NAME, sizeof d->name - 1, d->name, NULL);
	clGetDeviceInfo(id, CL_DEVICE_TYPE, sizeof t, &t, NULL);
	d->is_cpu = (t & CL_DEVICE_TYPE_CPU) != 0;
	size_t n = 0;
	if (clGetDeviceInfo(id, CL_DEVICE_EXTENSIONS, 0, NULL, &n) == CL_SUCCESS && n > 0) {
		char *ext = malloc(n + 1);
		if (ext && clGetDeviceInfo(id, CL_DEVICE_EXTENSIONS, n, ext, NULL) == CL_SUCCESS) {
			ext[n] = '\0';
			d->nv_options = strstr(ext, "cl_nv_compiler_options") != NULL;
		}
		free(ext);
	}
	device_selector_of(id, d->selector, sizeof d->selector);
	cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)platform, 0};
	d->ctx = clCreateContext(props, 1, &id, NULL, NULL, &err);
	if (!d->ctx)
		return cl_fail(d, "clCreateContext", err);
	d->queue = clCreateCommandQueue(d->ctx, id, 0, &err);
	if (!d->queue)
		return cl_fail(d, "clCreateCommandQueue", err);
	return AJAR_OK;
}

void device_close(Device *d)
{
	if (d->program)
		clReleaseProgram(d->program);
	if (d->queue)
		clReleaseCommandQueue(d->queue);
	if (d->ctx)
		clReleaseContext(d->ctx);
	memset(d, 0, sizeof *d);
}

const char *device_cache_dir(char *buf, size_t cap)
{
	const char *env = env_var(ENV_VAR_CACHE_DIR);
	const char *xdg = env_var(ENV_VAR_XDG_CACHE_HOME);
	const char *home = env_var(ENV_VAR_HOME);
	if (env && !strcmp(env, "off"))
		return NULL;
	if (env && env[0])
		snprintf(buf, cap, "%s", env);
	else if (xdg && xdg[0])
		snprintf(buf, cap, "%s/ajar", xdg);
	else if (home && home[0])
		snprintf(buf, cap, "%s/.cache/ajar", home);
	else
		return NULL;
	return buf;
}

#define FNV_BASIS 14695981039346656037ull
#define FNV_PRIME 1099511628211ull
/* Cache file header: CACHE_MAGIC, then the FNV-1a hash of the binary. */
#define CACHE_MAGIC "AJARBIN1"
#define CACHE_HEADER 16

static uint64_t fnv1a(uint64_t h, const char *s)
{
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * FNV_PRIME;
	return (h ^ 0xff) * FNV_PRIME; /* separator: "ab"+"c" != "a"+"bc" */
}

static uint64_t fnv1a_bytes(const unsigned char *p, size_t n)
{
	uint64_t h = FNV_BASIS;
	for (size_t i = 0; i < n; i++)
		h = (h ^ p[i]) * FNV_PRIME;
	return h;
}

static void cache_path(const Device *d, const char *source, const char *options, char *path, size_t cap)
{
	char dir[1024], drv[256] = "", pver[256] = "";
	clGetDeviceInfo(d->id, CL_DRIVER_VERSION, sizeof drv - 1, drv, NULL);
	clGetPlatformInfo(d->platform, CL_PLATFORM_VERSION, sizeof pver - 1, pver, NULL);
	uint64_t h = FNV_BASIS;
	h = fnv1a(h, source);
	h = fnv1a(h, options);
	h = fnv1a(h, d->name);
	h = fnv1a(h, drv);
	h = fnv1a(h, pver);
	if (!device_cache_dir(dir, sizeof dir)) {
		path[0] = '\0';
		return;
	}
	snprintf(path, cap, "%s/kernel-%016llx.bin", dir, (unsigned long long)h);
}

static unsigned char *read_file(const char *path, size_t *n)
{
	FILE *f = fopen(path, "rb");
	unsigned char *buf = NULL;
	long len;
	if (!f)
		return NULL;
	if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0) {
		buf = malloc((size_t)len);
		if (buf && fread(buf, 1, (size_t)len, f) != (size_t)len) {
			free(buf);
			buf = NULL;
		}
		*n = (size_t)len;
	}
	fclose(f);
	return buf;
}

/* Is this a whole cache file as cache_store wrote it? */
static int cache_valid(const unsigned char *file, size_t n)
{
	uint64_t h;
	if (n <= CACHE_HEADER || memcmp(file, CACHE_MAGIC, 8) != 0)
		return 0;
	memcpy(&h, file + 8, sizeof h);
	return h == fnv1a_bytes(file + CACHE_HEADER, n - CACHE_HEADER);
}

static void mkdirs(const char *path)
{
	char tmp[1200];
	snprintf(tmp, sizeof tmp, "%s", path);
	for (char *p = tmp + 1; *p; p++) {
		if (*p == '/') {
			*p = '\0';
			mkdir(tmp, 0755);
			*p = '/';
		}
	}
	mkdir(tmp, 0755);
}

/* Saving is best effort: a failure costs only the next start-up time. */
static void cache_store(const Device *d, const char *path)
{
	size_t size = 0;
	unsigned char *bin;
	char dir[1200], tmp[1232]; /* path: char[1200] in device_build */
	if (clGetProgramInfo(d->program, CL_PROGRAM_BINARY_SIZES, sizeof size, &size, NULL) != CL_SUCCESS ||
	    size == 0 || !(bin = malloc(size)))
		return;
	if (clGetProgramInfo(d->program, CL_PROGRAM_BINARIES, sizeof bin, &bin, NULL) == CL_SUCCESS) {
		snprintf(dir, sizeof dir, "%s", path);
		*strrchr(dir, '/') = '\0';
		mkdirs(dir);
		snprintf(tmp, sizeof tmp, "%s.%ld.tmp", path, (long)getpid());
		FILE *f = fopen(tmp, "wb");
		if (f) {
			uint64_t h = fnv1a_bytes(bin, size);
			int ok = fwrite(CACHE_MAGIC, 1, 8, f) == 8 && fwrite(&h, sizeof h, 1, f) == 1;
			ok &= fwrite(bin, 1, size, f) == size;
			ok &= fclose(f) == 0;
			if (!ok || rename(tmp, path) != 0)
				remove(tmp);
		}
	}
	free(bin);
}

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static ajar_status build_failed(Device *d, cl_int err)
{
	size_t n = 0;
	char *log;
	clGetProgramBuildInfo(d->program, d->id, CL_PROGRAM_BUILD_LOG, 0, NULL, &n);
	log = malloc(n + 1);
	if (log && clGetProgramBuildInfo(d->program, d->id, CL_PROGRAM_BUILD_LOG, n, log, NULL) == CL_SUCCESS) {
		log[n] = '\0';
		err_set(AJAR_ERROR_DEVICE, "OpenCL device %s: kernel build failed (%s):\n%s", d->name,
			cl_error_name(err), log);
	} else {
		err_set(AJAR_ERROR_DEVICE, "OpenCL device %s: kernel build failed (%s)", d->name,
			cl_error_name(err));
	}
	free(log);
	return AJAR_ERROR_DEVICE;
}

void device_build_options(const Device *d, int integrator, const char *extra, char *buf, size_t cap)
{
	/* bdpt's and portal's large functions stay calls on GPUs (CALLED in
	 * kernels/base/compat.h): inlined, NVIDIA's compiler did not finish them.
	 * On NVIDIA a register cap raises the work-items in flight by more
	 * than the spills cost. H100, Msamples/s, no cap / 40 / 32 registers
	 * (same images bit for bit): living-room pt 45.2 / 48.2 / 43.5, bdpt
	 * 2.95 / 3.71 / 3.47, portal 4.58 / 5.30 / 5.06; door-ajar portal
	 * 0.366 / 0.461 / 0.501; bathroom bdpt 2.10 / 2.24 / 2.62. */
	int bidirectional = integrator != INTEGRATOR_PT;
	char regs[40] = "";
	if (d->nv_options)
		snprintf(regs, sizeof regs, " -cl-nv-maxrregcount=%d", bidirectional ? 32 : 40);
	snprintf(buf, cap, KERNEL_OPTIONS "%d%s%s %s", integrator, bidirectional && !d->is_cpu ? " -DAJAR_CALLS" : "",
		 regs, extra ? extra : "");
}

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
	} omit[] = {{DEVICE_OMIT_ALPHA, "-DAJAR_NO_ALPHA "},
		    {DEVICE_OMIT_BENT_NORMALS, "-DAJAR_NO_BENT_NORMALS "},
		    {DEVICE_OMIT_TEXTURES, "-DAJAR_NO_TEXTURES "},
		    {DEVICE_OMIT_TRI_EXTRA, "-DAJAR_NO_TRI_EXTRA "},
		    {DEVICE_OMIT_PANES, "-DAJAR_NO_PANES "}};
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

ajar_status device_build(Device *d, const char *source, const char *options)
{
	char path[1200];
	size_t nbin = 0;
	unsigned char *bin;
	cl_int err, st;
	double t0 = now_seconds();
	cache_path(d, source, options, path, sizeof path);
	bin = path[0] ? read_file(path, &nbin) : NULL;
	if (bin && !cache_valid(bin, nbin)) {
		free(bin);
		bin = NULL;
	}
	if (bin) {
		const unsigned char *b = bin + CACHE_HEADER;
		nbin -= CACHE_HEADER;
		d->program = clCreateProgramWithBinary(d->ctx, 1, &d->id, &nbin, &b, &st, &err);
		free(bin);
		if (d->program && err == CL_SUCCESS && st == CL_SUCCESS &&
		    clBuildProgram(d->program, 1, &d->id, options, NULL, NULL) == CL_SUCCESS) {
			d->from_cache = 1;
			d->build_seconds = now_seconds() - t0;
			return AJAR_OK;
		}
		/* A binary the driver refuses (e.g. after a driver update):
		 * rebuild from source and overwrite it. */
		if (d->program)
			clReleaseProgram(d->program);
		d->program = NULL;
	}
	d->program = clCreateProgramWithSource(d->ctx, 1, &source, NULL, &err);
	if (!d->program)
		return cl_fail(d, "clCreateProgramWithSource", err);
	err = clBuildProgram(d->program, 1, &d->id, options, NULL, NULL);
	if (err != CL_SUCCESS)
		return build_failed(d, err);
	d->build_seconds = now_seconds() - t0;
	if (path[0])
		cache_store(d, path);
	return AJAR_OK;
}

ajar_status device_kernel(Device *d, const char *name, cl_kernel *out)
{
	cl_int err;
	*out = clCreateKernel(d->program, name, &err);
	if (!*out)
		return cl_fail(d, name, err);
	return AJAR_OK;
}

ajar_status device_buffer(Device *d, cl_mem_flags flags, size_t bytes, const void *host, cl_mem *out)
{
	cl_int err;
	if (bytes == 0) {
		bytes = 16; /* OpenCL forbids empty buffers; kernels never read it */
		host = NULL;
	}
	if (host)
		flags |= CL_MEM_COPY_HOST_PTR;
	*out = clCreateBuffer(d->ctx, flags, bytes, (void *)host, &err);
	if (!*out)
		return cl_fail(d, "clCreateBuffer", err);
	return AJAR_OK;
}
