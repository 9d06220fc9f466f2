/* device.c — one opened OpenCL device: its context and queue, kernels and
 * buffers, and the messages that name a failing call. Which devices there
 * are is device_select.c; the program it runs, device_build.c; how a pass
 * spreads over it, device_plan.c. */
#include "device/device.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

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

ajar_status device_reserve(const Device *d, const size_t *sizes, int n, const char *what)
{
	cl_ulong max_alloc = 0, global = 0;
	clGetDeviceInfo(d->id, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof max_alloc, &max_alloc, NULL);
	clGetDeviceInfo(d->id, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof global, &global, NULL);
	double total = 0, largest = 0;
	for (int i = 0; i < n; i++) {
		total += (double)sizes[i];
		largest = sizes[i] > largest ? (double)sizes[i] : largest;
	}
	const double mib = 1024.0 * 1024.0;
	if (max_alloc && largest > (double)max_alloc)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY,
			       "OpenCL device %s: %s need a buffer of %.0f MiB; the device allows %.0f MiB in one", d->name,
			       what, largest / mib, (double)max_alloc / mib);
	if (global && total > (double)global)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "OpenCL device %s: %s need %.0f MiB; the device has %.0f MiB",
			       d->name, what, total / mib, (double)global / mib);
	if (!d->is_cpu)
		return AJAR_OK;
	void **p = calloc((size_t)n + 1, sizeof *p);
	int ok = p != NULL;
	for (int i = 0; ok && i < n; i++)
		ok = (p[i] = malloc(sizes[i] ? sizes[i] : 1)) != NULL;
	for (int i = 0; p && i < n; i++)
		free(p[i]);
	free(p);
	if (!ok)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "OpenCL device %s: out of memory for %s (%.0f MiB)", d->name, what,
			       total / mib);
	return AJAR_OK;
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
	if (!host)
		flags &= ~(cl_mem_flags)CL_MEM_USE_HOST_PTR;
	else if (!(flags & CL_MEM_USE_HOST_PTR))
		flags |= CL_MEM_COPY_HOST_PTR;
	*out = clCreateBuffer(d->ctx, flags, bytes, (void *)host, &err);
	if (!*out)
		return cl_fail(d, "clCreateBuffer", err);
	return AJAR_OK;
}
