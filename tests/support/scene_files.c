/* scene_files.c — see scene_files.h. */
#include "scene_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void assert_v3(V3 a, float x, float y, float z)
{
	if (fabsf(a.x - x) > EPS || fabsf(a.y - y) > EPS || fabsf(a.z - z) > EPS)
		fail_msg("(%g, %g, %g) != (%g, %g, %g)", a.x, a.y, a.z, x, y, z);
}

void write_bytes(const char *name, const void *data, size_t n)
{
	char *p = test_tmp(name);
	FILE *f = fopen(p, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
	free(p);
}

void write_text(const char *name, const char *text) { write_bytes(name, text, strlen(text)); }

Scene *load_ok(const char *name)
{
	char *p = test_tmp(name);
	ajar_scene *s = NULL;
	ajar_status st = ajar_scene_load(p, &s);
	if (st)
		fail_msg("%s: %s", ajar_status_name(st), ajar_last_error());
	free(p);
	return s;
}

void load_fails(const char *name, ajar_status status, const char *needle)
{
	char *p = test_tmp(name);
	static char sentinel;
	ajar_scene *s = (ajar_scene *)(void *)&sentinel; /* must come back NULL */
	ajar_status st = ajar_scene_load(p, &s);
	const char *msg = ajar_last_error();
	if (st != status || !strstr(msg, name) || !strstr(msg, needle))
		fail_msg("%s: got %s \"%s\", want %s with \"%s\"", name, ajar_status_name(st), msg,
			 ajar_status_name(status), needle);
	assert_null(s);
	free(p);
}

size_t tri_bin(uint8_t *b, const uint16_t idx[3], float bad)
{
	const float pos[9] = {0, 0, 0, bad, 0, 0, 0, 1, 0};
	const float nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
	memcpy(b, pos, 36);
	memcpy(b + 36, nrm, 36);
	memcpy(b + 72, idx, 6);
	return 78;
}

const uint16_t idx012[3] = {0, 1, 2};

void write_tri_bin(void)
{
	uint8_t bin[80];
	write_bytes("tri.bin", bin, tri_bin(bin, idx012, 1.0f));
}

void write_tri_gltf(const char *name, const char *scene_nodes, const char *nodes, const char *more)
{
	write_tri_bin();
	char json[4096];
	snprintf(json, sizeof json,
		 "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[%s]%s}],\"nodes\":[%s]," TRI_BUFFERS(
			 "tri.bin") "," TRI_ACCESSORS(3) "}",
		 scene_nodes, more, nodes);
	write_text(name, json);
}

int warnings;
char last_warning[2048];

void count_warnings(ajar_log_level level, const char *message, void *user)
{
	if (level != AJAR_LOG_WARNING)
		return;
	warnings++;
	snprintf(last_warning, sizeof last_warning, "%s", message);
}
