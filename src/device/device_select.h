/* device_select.h — the OpenCL devices there are and which a selector list
 * chooses (device_select.c). The ground of src/device/ and the one header
 * that includes CL/cl.h: every file that drives OpenCL includes it through
 * device.h. */
#ifndef AJAR_DEVICE_SELECT_H
#define AJAR_DEVICE_SELECT_H
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>
#include <stddef.h>
#include <stdint.h>

#include "ajar.h"

/* Every device of every platform, in selector order ("P:D"). */
ajar_status device_list(ajar_device_info *out, uint32_t capacity, uint32_t *count);
/* Resolves a selector list: NULL/"" (the first CPU device, else the first
 * device), or comma-separated items, each "P:D", "N" (flat index), "cpu",
 * "gpu", a name substring (the first matching device not already chosen)
 * or "all" (every device not already chosen). Up to `cap` devices go to
 * platforms/ids in list order; an item that matches nothing is an error. */
ajar_status device_select(const char *selector, cl_platform_id *platforms, cl_device_id *ids,
			  uint32_t cap, uint32_t *count);
/* The "P:D" selector of a device ("?" if it is not enumerated). */
void device_selector_of(cl_device_id id, char *buf, size_t cap);
#endif
