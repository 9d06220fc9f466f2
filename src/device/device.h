/* device.h — one opened OpenCL device: context and queue, the program it
 * was built with (device_build.h), kernels, buffers, and errors that name
 * the failing call (device.c). Which devices there are: device_select.h;
 * how a pass spreads over one: device_plan.h. */
#ifndef AJAR_DEVICE_H
#define AJAR_DEVICE_H
#include <stddef.h>

#include "ajar.h"
#include "device/device_select.h"

typedef struct Device {
	cl_platform_id platform;
	cl_device_id id;
	char name[256];
	char selector[32];
	int is_cpu;
	int nv_options; /* the device takes NVIDIA's build options (cl_nv_compiler_options) */
	cl_context ctx;
	cl_command_queue queue;
	cl_program program;
	double build_seconds; /* source or cached binary to a built program */
	int from_cache;       /* 1 if the program came from Ajar's binary cache */
} Device;

ajar_status device_open(Device *d, cl_platform_id platform, cl_device_id id);
void device_close(Device *d);
ajar_status device_kernel(Device *d, const char *name, cl_kernel *out);
/* A buffer of `bytes`; with `host`, its contents copied from there, or the
 * host memory itself where flags has CL_MEM_USE_HOST_PTR (which must then
 * outlive the buffer and stay unchanged). */
ajar_status device_buffer(Device *d, cl_mem_flags flags, size_t bytes, const void *host, cl_mem *out);
/* Whether buffers of the n sizes can all be had on d, asked before any is
 * made: OpenCL's limits for one buffer and for all, and on a CPU device,
 * whose buffers are host memory that PoCL allocates only when a buffer is
 * first used (aborting the process when that fails), by allocating them
 * here at once and freeing them. AJAR_ERROR_OUT_OF_MEMORY naming `what`. */
ajar_status device_reserve(const Device *d, const size_t *sizes, int n, const char *what);

/* Names the failing call and the OpenCL error on the device. */
ajar_status cl_fail(const Device *d, const char *what, cl_int err);
const char *cl_error_name(cl_int err);
#define CL_TRY(d, call)                                              \
	do {                                                         \
		cl_int cl_try_err_ = (call);                         \
		if (cl_try_err_ != CL_SUCCESS)                       \
			return cl_fail((d), #call, cl_try_err_);     \
	} while (0)
#endif
