/* testutil.h — what every cmocka test binary shares: includes, the scene
 * directory, and small statistics (chi-square) used by sampling tests. */
#ifndef AJAR_TESTUTIL_H
#define AJAR_TESTUTIL_H
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#include <cmocka.h>

/* Path of a file in the source tree's scenes/ (tests run from the top). */
#define SCENE(p) "scenes/" p

/* Pearson chi-square test of observed counts against expected counts.
 * Cells with expected < min_expected are pooled (as Mitsuba's test does).
 * Returns the p-value; fails the caller's test if it is below `alpha`. */
double chi2_test(const double *observed, const double *expected, int ncells, double min_expected);

/* Upper tail of the chi-square distribution with `dof` degrees of freedom. */
double chi2_sf(double x, double dof);

/* A w x h equirectangular sky (linear RGB, malloc'd; kernels/light/env.h's
 * convention): a smooth gradient, brighter and bluer toward the zenith,
 * dim below the horizon, and a small, very bright sun disc of radiance
 * sun_l and angular radius `radius` about the unit direction (sun_x,
 * sun_y, sun_z). */
float *test_sun_sky(uint32_t w, uint32_t h, float sun_x, float sun_y, float sun_z, float radius, float sun_l);

/* A fresh temporary directory (removed by the caller) or NULL. */
char *test_tmpdir(void);
/* "dir/name", malloc'ed. */
char *test_path(const char *dir, const char *name);
/* Removes dir and everything under it (links are not followed). */
void test_remove_tree(const char *dir);
/* The one temporary-directory set-up of the test binaries: a group's
 * fixtures (cmocka_run_group_tests(tests, test_group_setup,
 * test_group_teardown)) that give the whole file one fresh directory,
 * test_dir, and remove it with everything in it afterwards. Setup fails
 * the group (-1) if no directory can be made. */
extern char *test_dir;
int test_group_setup(void **state);
int test_group_teardown(void **state);
/* "test_dir/name", malloc'ed. */
char *test_tmp(const char *name);
/* The ajar program the CLI tests run: $AJAR_BIN, else build/ajar. */
const char *test_ajar_bin(void);
/* Starts program `bin` with args (NULL-terminated, at most 46), its
 * standard output into file `out` and its errors into `err` (either NULL:
 * /dev/null), both made before it starts; returns the child's pid. */
pid_t test_spawn(const char *bin, const char *const *args, const char *out, const char *err);
/* Waits for pid, which must exit rather than die by a signal; its code. */
int test_wait_exit(pid_t pid);
/* The whole file at path (which must open), with a 0 after its bytes so
 * that text reads as a string; its length in *n unless n is NULL. */
char *test_read_file(const char *path, size_t *n);
/* tests/support/ajar_faults.c's program, beside the running test binary: the ajar
 * command with faults injected from AJAR_TEST_FAIL_DEVICE and
 * AJAR_TEST_PASS_SPP in its environment. */
const char *test_ajar_faults_bin(void);
#endif
