/* testutil.c — chi-square statistics and temp dirs for the tests. */
#include "testutil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

/* Regularized upper incomplete gamma Q(a, x), by series or continued
 * fraction (Numerical Recipes' split at x = a + 1). */
static double gamma_q(double a, double x)
{
	if (x <= 0)
		return 1.0;
	double gln = lgamma(a);
	if (x < a + 1) {
		double sum = 1.0 / a, del = sum, ap = a;
		for (int n = 0; n < 1000; n++) {
			ap += 1;
			del *= x / ap;
			sum += del;
			if (fabs(del) < fabs(sum) * 1e-15)
				break;
		}
		return 1.0 - sum * exp(-x + a * log(x) - gln);
	}
	double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
	for (int i = 1; i < 1000; i++) {
		double an = -i * (i - a);
		b += 2;
		d = an * d + b;
		if (fabs(d) < 1e-300)
			d = 1e-300;
		c = b + an / c;
		if (fabs(c) < 1e-300)
			c = 1e-300;
		d = 1 / d;
		double del = d * c;
		h *= del;
		if (fabs(del - 1) < 1e-15)
			break;
	}
	return exp(-x + a * log(x) - gln) * h;
}

double chi2_sf(double x, double dof) { return gamma_q(dof / 2, x / 2); }

double chi2_test(const double *obs, const double *expct, int n, double min_expected)
{
	double chsq = 0, pool_obs = 0, pool_exp = 0;
	int dof = 0;
	for (int i = 0; i < n; i++) {
		if (expct[i] < min_expected) {
			pool_obs += obs[i];
			pool_exp += expct[i];
			continue;
		}
		double d = obs[i] - expct[i];
		chsq += d * d / expct[i];
		dof++;
	}
	if (pool_exp > 0) {
		double d = pool_obs - pool_exp;
		chsq += d * d / pool_exp;
		dof++;
	}
	dof -= 1;
	if (dof < 1)
		return 1.0;
	return chi2_sf(chsq, dof);
}

char *test_tmpdir(void)
{
	char tmpl[] = "/tmp/ajar-test-XXXXXX";
	char *d = mkdtemp(tmpl);
	return d ? strdup(d) : NULL;
}

char *test_path(const char *dir, const char *name)
{
	size_t n = strlen(dir) + strlen(name) + 2;
	char *p = malloc(n);
	assert_non_null(p);
	snprintf(p, n, "%s/%s", dir, name);
	return p;
}

void test_remove_tree(const char *dir)
{
	DIR *d = opendir(dir);
	if (!d)
		return;
	struct dirent *e;
	while ((e = readdir(d))) {
		if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
			continue;
		char *p = test_path(dir, e->d_name);
		struct stat st;
		if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
			test_remove_tree(p);
		else
			unlink(p);
		free(p);
	}
	closedir(d);
	rmdir(dir);
}

char *test_dir;

int test_group_setup(void **state)
{
	(void)state;
	test_dir = test_tmpdir();
	return test_dir ? 0 : -1;
}

int test_group_teardown(void **state)
{
	(void)state;
	if (test_dir)
		test_remove_tree(test_dir);
	free(test_dir);
	test_dir = NULL;
	return 0;
}

char *test_tmp(const char *name) { return test_path(test_dir, name); }

const char *test_ajar_bin(void)
{
	const char *b = getenv("AJAR_BIN");
	return b && b[0] ? b : "build/ajar";
}

const char *test_ajar_faults_bin(void)
{
	static char path[4096];
	ssize_t n = readlink("/proc/self/exe", path, sizeof path - 32);
	if (n <= 0)
		return "build/release/tests/ajar_faults";
	path[n] = '\0';
	char *slash = strrchr(path, '/');
	strcpy(slash ? slash + 1 : path, "ajar_faults");
	return path;
}

float *test_sun_sky(uint32_t w, uint32_t h, float sun_x, float sun_y, float sun_z, float radius, float sun_l)
{
	float *rgb = malloc(sizeof(float) * 3 * w * h);
	if (!rgb)
		return NULL;
	for (uint32_t y = 0; y < h; y++)
		for (uint32_t x = 0; x < w; x++) {
			/* env_dir of the texel centre */
			double phi = 2.0 * M_PI * ((x + 0.5) / w - 0.5), theta = M_PI * (y + 0.5) / h;
			double dx = sin(theta) * sin(phi), dy = cos(theta), dz = -sin(theta) * cos(phi);
			float base = dy > 0.0 ? (float)(0.3 + 0.7 * dy) : (float)(0.1 + 0.05 * dy);
			float *p = rgb + 3 * (y * w + x);
			p[0] = 0.8f * base;
			p[1] = 0.9f * base + 0.1f * (float)(dx * dx);
			p[2] = 1.2f * base;
			if (dx * sun_x + dy * sun_y + dz * sun_z > cos(radius))
				p[0] = p[1] = p[2] = sun_l;
		}
	return rgb;
}

pid_t test_spawn(const char *bin, const char *const *args, const char *out, const char *err)
{
	const char *argv[48];
	int n = 0;
	argv[n++] = bin;
	while (args[n - 1] && n < 47) {
		argv[n] = args[n - 1];
		n++;
	}
	argv[n] = NULL;
	/* The files exist when this returns: a test may read them at once. */
	int fo = open(out ? out : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
	int fe = open(err ? err : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
	assert_true(fo >= 0 && fe >= 0);
	fflush(NULL); /* nothing buffered is written twice */
	pid_t pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		if (dup2(fo, 1) < 0 || dup2(fe, 2) < 0)
			_exit(127);
		execv(argv[0], (char *const *)argv);
		_exit(127);
	}
	close(fo);
	close(fe);
	return pid;
}

int test_wait_exit(pid_t pid)
{
	int status;
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status)); /* not killed by a signal */
	return WEXITSTATUS(status);
}

char *test_read_file(const char *path, size_t *n)
{
	FILE *f = fopen(path, "rb");
	if (!f)
		fail_msg("%s: cannot open", path);
	assert_int_equal(fseek(f, 0, SEEK_END), 0);
	long len = ftell(f);
	assert_true(len >= 0);
	rewind(f);
	char *b = malloc((size_t)len + 1);
	assert_non_null(b);
	assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
	b[len] = '\0';
	fclose(f);
	if (n)
		*n = (size_t)len;
	return b;
}
