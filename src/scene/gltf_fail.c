/* gltf_fail.c — the loader's errors: every message names the file, then
 * the element (gltf_loader.h). Apart from the readers that raise them, so
 * that the entry point (gltf_load.c) calls down into the readers alone. */
#include <stdarg.h>
#include <stdio.h>

#include "core/error.h"
#include "scene/gltf_loader.h"

ajar_status gltf_fail(const GltfLoader *L, ajar_status st, const char *fmt, ...)
{
	char buf[1536];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	return err_set(st, "%s: %s", L->file, buf);
}

ajar_status gltf_out_of_memory(const GltfLoader *L)
{
	return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", L->file);
}
