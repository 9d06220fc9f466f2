/* portals_gltf.c — `--portals-out FILE.gltf`: the found portals as a glTF
 * file a viewer shows over the scene (import both into Blender, or drop it
 * into any glTF viewer beside the scene): one translucent red quad per
 * portal, double-sided, each node named with its share and carrying
 * extras {"portal": true}, so the file's nodes, copied into the scene,
 * mark the same portals by hand. The buffer is embedded (a data URI); the
 * file is written under a temporary name and renamed. */
#include "cli/portals_gltf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/args.h"

static void base64(FILE *f, const unsigned char *p, size_t n)
{
	static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	for (size_t i = 0; i < n; i += 3) {
		unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
		fputc(tab[v >> 18 & 63], f);
		fputc(tab[v >> 12 & 63], f);
		fputc(i + 1 < n ? tab[v >> 6 & 63] : '=', f);
		fputc(i + 2 < n ? tab[v & 63] : '=', f);
	}
}

int portals_write_gltf(const char *path, const ajar_portal *p, uint32_t n)
{
	/* Per portal 4 corners (12 floats, 48 bytes) and 6 uint16 indices (12
	 * bytes): positions first, then indices. */
	size_t pos_bytes = 48 * (size_t)n, bytes = pos_bytes + 12 * (size_t)n;
	unsigned char *buf = malloc(bytes ? bytes : 1);
	if (!buf) {
		fprintf(stderr, "ajar: error: out of memory\n");
		return EXIT_NO_MEMORY;
	}
	for (uint32_t i = 0; i < n; i++) {
		float c[12];
		static const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
		for (int k = 0; k < 4; k++)
			for (int j = 0; j < 3; j++)
				c[3 * k + j] = p[i].center[j] + su[k] * p[i].half_u[j] + sv[k] * p[i].half_v[j];
		memcpy(buf + 48 * (size_t)i, c, sizeof c);
		uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
		memcpy(buf + pos_bytes + 12 * (size_t)i, idx, sizeof idx);
	}
	char tmp[4096];
	if (snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid()) >= (int)sizeof tmp) {
		free(buf);
		fprintf(stderr, "ajar: error: --portals-out %s: name too long\n", path);
		return EXIT_IO;
	}
	FILE *f = fopen(tmp, "w");
	if (!f) {
		fprintf(stderr, "ajar: error: --portals-out %s: %s\n", path, strerror(errno));
		free(buf);
		return EXIT_IO;
	}
	fprintf(f, "{\n\"asset\": {\"version\": \"2.0\", \"generator\": \"ajar %s (found portals)\"},\n", ajar_version());
	fprintf(f, "\"scene\": 0,\n\"scenes\": [{\"nodes\": [");
	for (uint32_t i = 0; i < n; i++)
		fprintf(f, "%s%u", i ? ", " : "", i);
	fprintf(f, "]}],\n\"nodes\": [");
	for (uint32_t i = 0; i < n; i++)
		fprintf(f, "%s\n  {\"name\": \"found portal %u (share %.1f%%)\", \"mesh\": %u, \"extras\": {\"portal\": true}}",
			i ? "," : "", i, 100.0 * p[i].share, i);
	fprintf(f, "],\n\"meshes\": [");
	for (uint32_t i = 0; i < n; i++)
		fprintf(f, "%s\n  {\"primitives\": [{\"attributes\": {\"POSITION\": %u}, \"indices\": %u, \"material\": 0}]}",
			i ? "," : "", 2 * i, 2 * i + 1);
	fprintf(f, "],\n\"materials\": [{\"name\": \"found portal\", \"doubleSided\": true, \"alphaMode\": \"BLEND\",\n"
		   "  \"pbrMetallicRoughness\": {\"baseColorFactor\": [1, 0.1, 0.05, 0.5], \"metallicFactor\": 0, "
		   "\"roughnessFactor\": 1}}],\n");
	fprintf(f, "\"accessors\": [");
	for (uint32_t i = 0; i < n; i++) {
		float lo[3], hi[3];
		for (int j = 0; j < 3; j++) {
			lo[j] = hi[j] = p[i].center[j];
			for (int k = 0; k < 4; k++) {
				float v = p[i].center[j] + (k & 1 ? 1 : -1) * p[i].half_u[j] + (k & 2 ? 1 : -1) * p[i].half_v[j];
				lo[j] = v < lo[j] ? v : lo[j];
				hi[j] = v > hi[j] ? v : hi[j];
			}
		}
		fprintf(f,
			"%s\n  {\"bufferView\": 0, \"byteOffset\": %u, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", "
			"\"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]},"
			"\n  {\"bufferView\": 1, \"byteOffset\": %u, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}",
			i ? "," : "", 48 * i, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], 12 * i);
	}
	fprintf(f, "],\n\"bufferViews\": [");
	if (n)
		fprintf(f, "{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": %zu, \"target\": 34962}, "
			   "{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu, \"target\": 34963}",
			pos_bytes, pos_bytes, bytes - pos_bytes);
	fprintf(f, "],\n\"buffers\": [");
	if (n) {
		fprintf(f, "{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,", bytes);
		base64(f, buf, bytes);
		fprintf(f, "\"}");
	}
	fprintf(f, "]\n}\n");
	free(buf);
	int bad = ferror(f);
	bad |= fclose(f) != 0;
	if (bad || rename(tmp, path) != 0) {
		fprintf(stderr, "ajar: error: --portals-out %s: %s\n", path, strerror(errno ? errno : EIO));
		unlink(tmp);
		return EXIT_IO;
	}
	return EXIT_OK;
}
