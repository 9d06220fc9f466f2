/* device_build.c — a device's program: the build options, the build, and
 * the binary cache.
 *
 * Program binaries are cached per device and per hash of (source, options,
 * device name, driver and platform version), so the second run of the same
 * build skips the OpenCL C front end. Cache files are written to a temporary
 * name and renamed, so concurrent renders never read a half-written binary.
 * A file starts with a magic and a hash of the binary that follows: some
 * drivers (PoCL 3.1) crash on a damaged binary instead of rejecting it, so
 * a file that fails the check is never handed to the driver. */
#include "device/device_build.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/env_vars.h"
#include "core/error.h"
#include "device/kernel_source.h"
#include "base/types.h"

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
