/* portals_gltf.h — found portals written as a glTF file (portals_gltf.c). */
#ifndef AJAR_CLI_PORTALS_GLTF_H
#define AJAR_CLI_PORTALS_GLTF_H
#include <stdint.h>

#include "ajar.h"

/* Writes the n portals to `path` (temporary name, renamed); an exit code,
 * the error printed. */
int portals_write_gltf(const char *path, const ajar_portal *p, uint32_t n);
#endif
