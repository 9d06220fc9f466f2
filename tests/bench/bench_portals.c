/* bench_portals.c — `make bench-portals`: found portals against marked ones
 * at equal time, on every shipped scene that marks portals.
 *
 * Per scene, three renders of the same size and time limit, two seeds each:
 *   marked  the scene as shipped, with the integrator named for it;
 *   found   the scene with its portal nodes taken out (cleared after
 *           loading: what an exporter without custom properties hands over)
 *           rendered with default options but that integrator, so the
 *           search finds the portals;
 *   none    the same stripped scene with pt and no portals
 *           (AJAR_PORTALS_NONE): a new user's render without any.
 * Error measure (no reference needed; every render is unbiased): the
 * relative variance of one render, mean over pixels and channels of
 * (a - b)^2 / 2 / (r^2 + (0.1 mean r)^2), a and b the two seeds' images and
 * r the mean of all six renders: relMSE at equal time. The machine may be
 * shared, and a render's samples then follow the others' load: the ratios
 * are taken at equal CPU time, relvar x CPU seconds of the render (user and
 * system, every thread; relMSE at equal CPU time is proportional to it),
 * and at equal wall time as rendered. Printed: spp, the error, CPU
 * seconds, found/marked (the target: at most 1.25) and none/found (at least
 * 5), and the search's time beside the render time.
 *
 * AJAR_BENCH_SECONDS (default 10) per render, AJAR_BENCH_SIZE (default 64),
 * AJAR_BENCH_SCENES (comma-separated names) picks scenes; each scene's
 * integrator may be forced with AJAR_BENCH_INTEGRATOR=pt|bdpt|portal.
 * Arguments FILE.gltf[:pt|bdpt|portal] (default portal) bench those files
 * instead of the shipped scenes: layouts not shipped, a door at another
 * angle (make_door_ajar.py --angle). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "ajar.h"
#include "scene/scene.h"

typedef struct {
	const char *name;
	ajar_integrator integ; /* the integrator the README names for it */
} BenchScene;

static const BenchScene scenes[] = {
	{"window-room", AJAR_INTEGRATOR_PT},		{"window-room-forest", AJAR_INTEGRATOR_PORTAL},
	{"window-room-sunset", AJAR_INTEGRATOR_PORTAL}, {"window-room-sun", AJAR_INTEGRATOR_PORTAL},
	{"living-room", AJAR_INTEGRATOR_PT},		{"living-room-forest", AJAR_INTEGRATOR_PORTAL},
	{"atrium-forest", AJAR_INTEGRATOR_PORTAL},	{"door-ajar", AJAR_INTEGRATOR_PORTAL},
	{"door-ajar-lamp", AJAR_INTEGRATOR_PORTAL},	{"bathroom", AJAR_INTEGRATOR_BDPT},
};

static ajar_integrator integ_of(const char *name)
{
	return !strcmp(name, "pt") ? AJAR_INTEGRATOR_PT : !strcmp(name, "bdpt") ? AJAR_INTEGRATOR_BDPT : AJAR_INTEGRATOR_PORTAL;
}

static const char *integ_name(ajar_integrator i)
{
	return i == AJAR_INTEGRATOR_PT ? "pt" : i == AJAR_INTEGRATOR_BDPT ? "bdpt" : "portal";
}

static void check(ajar_status st)
{
	if (st != AJAR_OK) {
		fprintf(stderr, "bench_portals: %s\n", ajar_last_error());
		exit(1);
	}
}

/* Renders two seeds of s for `secs` each into img[0], img[1]. */
static double cpu_seconds(void)
{
	struct rusage u;
	getrusage(RUSAGE_SELF, &u);
	return u.ru_utime.tv_sec + u.ru_utime.tv_usec * 1e-6 + u.ru_stime.tv_sec + u.ru_stime.tv_usec * 1e-6;
}

static void render2(ajar_scene *s, ajar_integrator integ, ajar_portals portals, uint32_t size, double secs, float *img[2],
		    uint32_t spp[2], double *search, double *cpu)
{
	ajar_options o;
	ajar_options_default(&o);
	o.width = o.height = size;
	o.spp = 0;
	o.time_limit = secs;
	o.integrator = integ;
	o.portals = portals;
	ajar_renderer *r;
	check(ajar_renderer_create(s, &o, &r));
	uint32_t n = 0;
	*search = 0.0;
	check(ajar_renderer_found_portals(r, NULL, 0, &n, search));
	*cpu = 0.0;
	for (int k = 0; k < 2; k++) {
		check(ajar_renderer_restart(r, 1000u + 17u * (uint32_t)k));
		double c0 = cpu_seconds();
		check(ajar_renderer_render(r, NULL, NULL));
		*cpu += 0.5 * (cpu_seconds() - c0);
		check(ajar_renderer_image(r, img[k], NULL, NULL));
		spp[k] = ajar_renderer_spp(r);
	}
	ajar_renderer_destroy(&r);
}

static double rel_var(float *const img[2], const double *ref, size_t npix)
{
	double mean = 0.0, e = 0.0;
	for (size_t i = 0; i < npix; i++)
		for (int c = 0; c < 3; c++)
			mean += ref[3 * i + c];
	mean /= 3.0 * npix;
	for (size_t i = 0; i < npix; i++)
		for (int c = 0; c < 3; c++) {
			double d = (double)img[0][4 * i + c] - img[1][4 * i + c], r = ref[3 * i + c];
			e += d * d / 2.0 / (r * r + 0.01 * mean * mean);
		}
	return e / (3.0 * npix);
}

int main(int argc, char **argv)
{
	double secs = getenv("AJAR_BENCH_SECONDS") ? atof(getenv("AJAR_BENCH_SECONDS")) : 10.0;
	uint32_t size = getenv("AJAR_BENCH_SIZE") ? (uint32_t)atoi(getenv("AJAR_BENCH_SIZE")) : 64;
	const char *only = getenv("AJAR_BENCH_SCENES"), *force = getenv("AJAR_BENCH_INTEGRATOR");
	size_t npix = (size_t)size * size;
	printf("found portals against marked ones: %ux%u, %.0f s a render, two seeds; relative variance of one render\n",
	       size, size, secs);
	printf("%-19s %-6s %-24s %-24s %-24s %7s %8s %7s %8s %8s\n", "scene", "integ", "marked (spp relvar cpu)",
	       "found (spp relvar cpu)", "none, pt (spp relvar cpu)", "fnd/mrk", "none/fnd", "(wall:", "f/m", "n/f)");
	printf("%-19s %-6s %-24s %-24s %-24s %7s %8s %7s %8s %8s\n", "", "", "", "", "", "cpu", "cpu", "", "", "");
	size_t nscenes = argc > 1 ? (size_t)argc - 1 : sizeof scenes / sizeof scenes[0];
	for (size_t i = 0; i < nscenes; i++) {
		char path[256], name[64];
		BenchScene arg = {name, AJAR_INTEGRATOR_PORTAL};
		const BenchScene *b = &scenes[i];
		if (argc > 1) {
			snprintf(path, sizeof path, "%s", argv[i + 1]);
			char *colon = strrchr(path, ':');
			if (colon) {
				*colon = '\0';
				arg.integ = integ_of(colon + 1);
			}
			size_t len = strlen(path); /* its tail names it: scenes often share file names */
			snprintf(name, sizeof name, "%.63s", len > 19 ? path + len - 19 : path);
			b = &arg;
		} else {
			snprintf(path, sizeof path, "scenes/%s/%s.gltf", b->name, b->name);
		}
		if (only && argc <= 1) {
			char pad[256];
			snprintf(pad, sizeof pad, ",%s,", only);
			char key[64];
			snprintf(key, sizeof key, ",%s,", b->name);
			if (!strstr(pad, key))
				continue;
		}
		ajar_integrator integ = b->integ;
		if (force)
			integ = integ_of(force);
		ajar_scene *marked, *stripped;
		check(ajar_scene_load(path, &marked));
		check(ajar_scene_load(path, &stripped));
		stripped->nportal_tris = stripped->nportals = 0; /* the portal nodes taken out */
		float *img[3][2];
		uint32_t spp[3][2];
		double search[3], cpu[3];
		for (int v = 0; v < 3; v++)
			for (int k = 0; k < 2; k++)
				img[v][k] = malloc(sizeof(float) * 4 * npix);
		render2(marked, integ, AJAR_PORTALS_DEFAULT, size, secs, img[0], spp[0], &search[0], &cpu[0]);
		render2(stripped, integ, AJAR_PORTALS_DEFAULT, size, secs, img[1], spp[1], &search[1], &cpu[1]);
		render2(stripped, AJAR_INTEGRATOR_PT, AJAR_PORTALS_NONE, size, secs, img[2], spp[2], &search[2], &cpu[2]);
		double *ref = calloc(3 * npix, sizeof *ref);
		for (int v = 0; v < 3; v++)
			for (int k = 0; k < 2; k++)
				for (size_t p = 0; p < npix; p++)
					for (int c = 0; c < 3; c++)
						ref[3 * p + c] += img[v][k][4 * p + c] / 6.0;
		double e[3];
		for (int v = 0; v < 3; v++)
			e[v] = rel_var(img[v], ref, npix);
		char cell[3][40];
		for (int v = 0; v < 3; v++)
			snprintf(cell[v], sizeof cell[v], "%u %.3g %.1f", (spp[v][0] + spp[v][1]) / 2, e[v], cpu[v]);
		printf("%-19s %-6s %-24s %-24s %-24s %7.2f %8.1f %7s %8.2f %8.1f   search %.3f s\n", b->name,
		       integ_name(integ), cell[0], cell[1], cell[2], e[1] * cpu[1] / (e[0] * cpu[0]),
		       e[2] * cpu[2] / (e[1] * cpu[1]), "", e[1] / e[0], e[2] / e[1], search[1]);
		fflush(stdout);
		for (int v = 0; v < 3; v++)
			for (int k = 0; k < 2; k++)
				free(img[v][k]);
		free(ref);
		ajar_scene_destroy(&marked);
		ajar_scene_destroy(&stripped);
	}
	return 0;
}
