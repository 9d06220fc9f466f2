/* fuzz_common.c — see fuzz_common.h. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[256];

static void remove_dir(void)
{
	char cmd[300];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
	if (system(cmd) != 0)
		fprintf(stderr, "fuzz: could not remove %s\n", dir);
}

const char *fuzz_path(const char *name)
{
	static char paths[16][320];
	static int used;
	if (!dir[0]) {
		const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
		snprintf(dir, sizeof dir, "%s/ajar-fuzz-XXXXXX", base);
		if (!mkdtemp(dir))
			abort();
		atexit(remove_dir);
	}
	for (int i = 0; i < used; i++)
		if (!strcmp(strrchr(paths[i], '/') + 1, name))
			return paths[i];
	if (used == 16)
		abort();
	snprintf(paths[used], sizeof paths[used], "%s/%s", dir, name);
	return paths[used++];
}

const char *fuzz_write(const char *name, const uint8_t *data, size_t n)
{
	const char *p = fuzz_path(name);
	FILE *f = fopen(p, "wb");
	if (!f || fwrite(data, 1, n, f) != n || fclose(f) != 0)
		abort();
	return p;
}
