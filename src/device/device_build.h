/* device_build.h — a device's program: its build options, and the build
 * with a binary cache (device_build.c). */
#ifndef AJAR_DEVICE_BUILD_H
#define AJAR_DEVICE_BUILD_H
#include <stddef.h>

#include "device/device.h"

/* Builds `source` with `options` into d->program, reusing a cached binary
 * for this device, driver, source and options when one exists. Build logs
 * go into the error. */
ajar_status device_build(Device *d, const char *source, const char *options);
/* The build options of integrator `integrator` (INTEGRATOR_*) on d:
 * KERNEL_OPTIONS, then -DAJAR_CALLS for bdpt and portal on a device that
 * is not a CPU, a register cap where the device takes NVIDIA's options,
 * and last `extra` (AJAR_CL_OPTIONS, NULL for none), which can undo both. */
void device_build_options(const Device *d, int integrator, const char *extra, char *buf, size_t cap);
/* Where compiled kernels are cached: $AJAR_CACHE_DIR, else
 * $XDG_CACHE_HOME/ajar, else ~/.cache/ajar; NULL disables the cache. */
const char *device_cache_dir(char *buf, size_t cap);
#endif
