/* args.c — hand-written parsing of `ajar render`'s options: each option
 * takes its value as the next argument or after '=' (`--spp 16`,
 * `--spp=16`), numbers are checked whole (no sign, no trailing text, in
 * range) and every error names the option it is about. */
#include "cli/args.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest image side we accept; far beyond any sensible render, small
 * enough that width * height * 16 bytes cannot overflow anywhere. */
#define MAX_SIDE 65536u

int args_usage_error(const char *fmt, ...)
{
	va_list ap;
	fputs("ajar: error: ", stderr);
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fputs(" (see 'ajar --help')\n", stderr);
	return EXIT_USAGE;
}

const char *args_integrator_name(ajar_integrator i)
{
	switch (i) {
	case AJAR_INTEGRATOR_PT: return "pt";
	case AJAR_INTEGRATOR_BDPT: return "bdpt";
	case AJAR_INTEGRATOR_PORTAL: return "portal";
	}
	return "?";
}

/* A decimal integer in [min, max], digits only. */
static int parse_u32(const char *opt, const char *s, uint32_t min, uint32_t max, uint32_t *out)
{
	if (!isdigit((unsigned char)s[0]))
		return args_usage_error("%s: '%s' is not a whole number >= %u", opt, s, min);
	errno = 0;
	char *end;
	unsigned long long v = strtoull(s, &end, 10);
	if (*end != '\0')
		return args_usage_error("%s: '%s' is not a whole number >= %u", opt, s, min);
	if (errno == ERANGE || v < min || v > max)
		return args_usage_error("%s: %s is out of range (%u to %u)", opt, s, min, max);
	*out = (uint32_t)v;
	return EXIT_OK;
}

static int parse_seconds(const char *opt, const char *s, double *out)
{
	char *end;
	errno = 0;
	double v = strtod(s, &end);
	if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v) || !(v > 0) || isspace((unsigned char)s[0]))
		return args_usage_error("%s: '%s' is not a positive number of seconds", opt, s);
	*out = v;
	return EXIT_OK;
}

/* WxH, both sides positive. */
static int parse_size(const char *opt, const char *s, uint32_t *w, uint32_t *h)
{
	const char *x = strpbrk(s, "xX");
	char ws[32];
	if (!x || (size_t)(x - s) >= sizeof ws || x == s)
		return args_usage_error("%s: '%s' is not WIDTHxHEIGHT (e.g. 640x480)", opt, s);
	memcpy(ws, s, (size_t)(x - s));
	ws[x - s] = '\0';
	if (!isdigit((unsigned char)ws[0]) || !isdigit((unsigned char)x[1]))
		return args_usage_error("%s: '%s' is not WIDTHxHEIGHT (e.g. 640x480)", opt, s);
	if (parse_u32(opt, ws, 1, MAX_SIDE, w) != EXIT_OK || parse_u32(opt, x + 1, 1, MAX_SIDE, h) != EXIT_OK)
		return EXIT_USAGE;
	return EXIT_OK;
}

static int parse_integrator(const char *opt, const char *s, ajar_integrator *out)
{
	static const ajar_integrator all[] = {AJAR_INTEGRATOR_PT, AJAR_INTEGRATOR_BDPT, AJAR_INTEGRATOR_PORTAL};
	for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
		if (strcmp(s, args_integrator_name(all[i])) == 0) {
			*out = all[i];
			return EXIT_OK;
		}
	return args_usage_error("%s: '%s' is not one of pt, bdpt, portal", opt, s);
}

/* --aov: a comma-separated list of albedo, normal, depth, variance. */
static int parse_aov(const char *opt, const char *s, uint32_t *out)
{
	static const struct {
		const char *name;
		uint32_t bit;
	} aovs[] = {{"albedo", AJAR_AOV_ALBEDO}, {"normal", AJAR_AOV_NORMAL}, {"depth", AJAR_AOV_DEPTH},
		    {"variance", AJAR_AOV_VARIANCE}};
	*out = 0;
	for (const char *p = s; *p;) {
		size_t n = strcspn(p, ",");
		size_t k = 0;
		while (k < sizeof aovs / sizeof aovs[0] && (strlen(aovs[k].name) != n || strncmp(p, aovs[k].name, n)))
			k++;
		if (k == sizeof aovs / sizeof aovs[0])
			return args_usage_error("%s: '%.*s' is not one of albedo, normal, depth, variance", opt, (int)n, p);
		*out |= aovs[k].bit;
		p += n;
		if (*p == ',' && *++p == '\0')
			return args_usage_error("%s: '%s' ends with a comma", opt, s);
	}
	return EXIT_OK;
}

const char *args_portals_name(ajar_portals p)
{
	switch (p) {
	case AJAR_PORTALS_DEFAULT: return "default";
	case AJAR_PORTALS_MARKED: return "marked";
	case AJAR_PORTALS_FOUND: return "auto";
	case AJAR_PORTALS_NONE: return "none";
	}
	return "?";
}

/* A finite number in [lo, hi], the whole string. */
static int parse_number(const char *opt, const char *s, double lo, double hi, float *out)
{
	char *end;
	errno = 0;
	double v = strtod(s, &end);
	if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v) || isspace((unsigned char)s[0]))
		return args_usage_error("%s: '%s' is not a number", opt, s);
	if (v < lo || v > hi)
		return args_usage_error("%s: %s is out of range (%g to %g)", opt, s, lo, hi);
	*out = (float)v;
	return EXIT_OK;
}

/* Three comma-separated numbers, each in [lo[k], hi[k]]. */
static int parse_triple(const char *opt, const char *s, const char *form, const double lo[3], const double hi[3],
			float out[3])
{
	char buf[128];
	if (strlen(s) >= sizeof buf)
		return args_usage_error("%s: '%s' is not %s", opt, s, form);
	snprintf(buf, sizeof buf, "%s", s);
	char *p = buf;
	for (int k = 0; k < 3; k++) {
		char *comma = strchr(p, ',');
		if ((k < 2) != (comma != NULL))
			return args_usage_error("%s: '%s' is not %s", opt, s, form);
		if (comma)
			*comma = '\0';
		if (parse_number(opt, p, lo[k], hi[k], &out[k]) != EXIT_OK)
			return EXIT_USAGE;
		p = comma ? comma + 1 : p;
	}
	return EXIT_OK;
}

/* The options that change the scene (SceneArgs): EXIT_OK or EXIT_USAGE
 * when `name` is one of them, -1 when it is not. */
static int parse_scene_option(const char *name, const char *val, SceneArgs *sc)
{
	static const double big = 1e30;
	if (!strcmp(name, "--sky")) {
		sc->sky = val;
		return EXIT_OK;
	}
	if (!strcmp(name, "--portals-out")) {
		sc->portals_out = val;
		return EXIT_OK;
	}
	if (!strcmp(name, "--sky-strength")) {
		sc->sky_strength_given = 1;
		return parse_number(name, val, 0.0, big, &sc->sky_strength);
	}
	if (!strcmp(name, "--sky-rotation")) {
		sc->sky_rotation_given = 1;
		return parse_number(name, val, -1e6, 1e6, &sc->sky_rotation);
	}
	if (!strcmp(name, "--sky-color")) {
		static const double lo[3] = {0, 0, 0}, hi[3] = {big, big, big};
		sc->sky_color_given = 1;
		return parse_triple(name, val, "R,G,B (three numbers >= 0)", lo, hi, sc->sky_color);
	}
	if (!strcmp(name, "--sun")) {
		static const double lo[3] = {-90, -360, 0}, hi[3] = {90, 360, big};
		sc->sun_given = 1;
		return parse_triple(name, val, "ELEVATION,AZIMUTH,LUX (degrees, degrees, lux)", lo, hi, sc->sun);
	}
	if (!strcmp(name, "--portals")) {
		static const ajar_portals all[] = {AJAR_PORTALS_MARKED, AJAR_PORTALS_FOUND, AJAR_PORTALS_NONE,
						   AJAR_PORTALS_DEFAULT};
		for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
			if (!strcmp(val, args_portals_name(all[i]))) {
				sc->portals = all[i];
				return EXIT_OK;
			}
		return args_usage_error("%s: '%s' is not one of marked, auto, none", name, val);
	}
	return -1;
}

/* What the scene options must agree on. */
static int check_scene_options(const SceneArgs *sc)
{
	if (sc->sky && sc->sky_color_given)
		return args_usage_error("--sky and --sky-color: give one sky");
	if (sc->sky_strength_given && !sc->sky && !sc->sky_color_given)
		return args_usage_error("--sky-strength needs --sky FILE or --sky-color R,G,B");
	return EXIT_OK;
}

/* Splits "--opt=value" (name gets "--opt") or takes the next argument. */
static int option_value(int argc, char **argv, int *i, char *name, size_t cap, const char **val)
{
	const char *arg = argv[*i], *eq = strchr(arg, '=');
	if (eq && arg[1] == '-') {
		size_t n = (size_t)(eq - arg);
		if (n >= cap)
			return args_usage_error("unknown option '%.*s'", (int)n, arg);
		memcpy(name, arg, n);
		name[n] = '\0';
		*val = eq + 1;
	} else {
		snprintf(name, cap, "%s", arg);
		*val = NULL;
	}
	return EXIT_OK;
}

int args_parse_info(int argc, char **argv, InfoArgs *a)
{
	memset(a, 0, sizeof *a);
	for (int i = 0; i < argc; i++) {
		const char *arg = argv[i];
		if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
			a->help = 1;
			return EXIT_OK;
		}
		if (!strcmp(arg, "--allow-outside-files")) {
			a->allow_outside_files = 1;
			continue;
		}
		if (arg[0] != '-' || arg[1] == '\0') {
			if (a->scene)
				return args_usage_error("info: expects one scene, got '%s' and '%s'", a->scene, arg);
			a->scene = arg;
			continue;
		}
		char name[32];
		const char *val = NULL;
		if (option_value(argc, argv, &i, name, sizeof name, &val) != EXIT_OK)
			return EXIT_USAGE;
		static const char *const known[] = {"--portals", "--portals-out", "--sky", "--sky-color", "--sky-strength",
						    "--sky-rotation", "--sun"};
		size_t k = 0;
		while (k < sizeof known / sizeof known[0] && strcmp(name, known[k]) != 0)
			k++;
		if (k == sizeof known / sizeof known[0])
			return args_usage_error("info: unknown option '%s'", name);
		if (!val) {
			if (i + 1 >= argc)
				return args_usage_error("%s needs a value", name);
			val = argv[++i];
		}
		if (val[0] == '\0')
			return args_usage_error("%s: empty value", name);
		if (parse_scene_option(name, val, &a->sc) != EXIT_OK)
			return EXIT_USAGE;
	}
	if (!a->scene)
		return args_usage_error("info: no scene given");
	a->search = a->sc.portals == AJAR_PORTALS_FOUND;
	return check_scene_options(&a->sc);
}

int args_parse_render(int argc, char **argv, RenderArgs *a)
{
	memset(a, 0, sizeof *a);
	ajar_options_default(&a->opt);
	int spp_given = 0, time_given = 0, noise_given = 0;
	uint32_t strategy_len = 0;
	for (int i = 0; i < argc; i++) {
		const char *arg = argv[i];
		if (arg[0] != '-' || arg[1] == '\0') { /* "-" alone is a (strange) file name */
			if (a->scene)
				return args_usage_error("more than one scene given ('%s' and '%s')", a->scene, arg);
			a->scene = arg;
			continue;
		}
		if (!strcmp(arg, "--")) {
			if (i + 2 != argc || a->scene)
				return args_usage_error("'--' must be followed by exactly one scene");
			a->scene = argv[++i];
			continue;
		}
		if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
			a->help = 1;
			return EXIT_OK;
		}
		if (!strcmp(arg, "-q") || !strcmp(arg, "--quiet")) {
			a->quiet = 1;
			continue;
		}
		if (!strcmp(arg, "--unweighted")) {
			a->opt.strategy_unweighted = 1;
			a->given |= GIVEN_UNWEIGHTED;
			continue;
		}
		if (!strcmp(arg, "--allow-outside-files")) {
			a->allow_outside_files = 1;
			continue;
		}
		/* Every other option takes a value: "--opt value" or "--opt=value". */
		char name[32];
		const char *val, *eq = strchr(arg, '=');
		if (eq && arg[1] == '-') {
			size_t n = (size_t)(eq - arg);
			if (n >= sizeof name)
				return args_usage_error("unknown option '%.*s'", (int)n, arg);
			memcpy(name, arg, n);
			name[n] = '\0';
			val = eq + 1;
		} else {
			snprintf(name, sizeof name, "%s", arg);
			val = NULL;
		}
		static const char *const known[] = {"-o", "--output", "--spp", "--time", "--size", "--integrator",
						    "--max-depth", "--seed", "--device", "--png", "--min-depth",
						    "--mis", "--strategies", "--strategy-len", "--exposure",
						    "--checkpoint", "--checkpoint-every", "--resume", "--aov", "--portals",
						    "--portals-out", "--sky", "--sky-color", "--sky-strength", "--sky-rotation",
						    "--sun", "--noise"};
		size_t k = 0;
		while (k < sizeof known / sizeof known[0] && strcmp(name, known[k]) != 0)
			k++;
		if (k == sizeof known / sizeof known[0])
			return args_usage_error("unknown option '%s'", eq ? name : arg);
		if (!val) {
			if (i + 1 >= argc)
				return args_usage_error("%s needs a value", name);
			val = argv[++i];
		}
		if (val[0] == '\0')
			return args_usage_error("%s: empty value", name);
		int rc = parse_scene_option(name, val, &a->sc);
		if (rc == EXIT_USAGE)
			return rc;
		int scene_option = rc == EXIT_OK;
		rc = EXIT_OK;
		if (scene_option)
			a->opt.portals = a->sc.portals;
		else if (!strcmp(name, "-o") || !strcmp(name, "--output"))
			a->exr = val;
		else if (!strcmp(name, "--png"))
			a->png = val;
		else if (!strcmp(name, "--device"))
			a->opt.device = val;
		else if (!strcmp(name, "--checkpoint"))
			a->checkpoint = val;
		else if (!strcmp(name, "--resume"))
			a->resume = val;
		else if (!strcmp(name, "--aov"))
			rc = parse_aov(name, val, &a->opt.aov);
		else if (!strcmp(name, "--noise")) {
			float pct;
			rc = parse_number(name, val, 0.0, 100.0, &pct);
			if (rc == EXIT_OK && !(pct > 0.0f && pct < 100.0f))
				rc = args_usage_error("--noise: %s is not a percentage between 0 and 100 (excluded)", val);
			a->opt.noise = pct / 100.0;
			noise_given = 1;
		} else if (!strcmp(name, "--checkpoint-every"))
			rc = parse_seconds(name, val, &a->checkpoint_every);
		else if (!strcmp(name, "--spp")) {
			rc = parse_u32(name, val, 1, UINT32_MAX, &a->opt.spp);
			spp_given = 1;
		} else if (!strcmp(name, "--time")) {
			rc = parse_seconds(name, val, &a->opt.time_limit);
			time_given = 1;
		} else if (!strcmp(name, "--size"))
			rc = parse_size(name, val, &a->opt.width, &a->opt.height);
		else if (!strcmp(name, "--integrator"))
			rc = parse_integrator(name, val, &a->opt.integrator);
		else if (!strcmp(name, "--max-depth"))
			rc = parse_u32(name, val, 1, 1024, &a->opt.max_depth);
		else if (!strcmp(name, "--min-depth"))
			rc = parse_u32(name, val, 0, 1024, &a->opt.min_depth);
		else if (!strcmp(name, "--strategy-len"))
			rc = parse_u32(name, val, 1, 8, &strategy_len);
		else if (!strcmp(name, "--strategies"))
			a->strategies = val;
		else if (!strcmp(name, "--exposure")) {
			char *end;
			a->exposure = strtod(val, &end);
			if (*end || !(a->exposure >= -30 && a->exposure <= 30))
				rc = args_usage_error("--exposure: '%s' is not a number in -30..30", val);
		}
		else if (!strcmp(name, "--mis")) {
			if (!strcmp(val, "auto"))
				a->opt.mis = AJAR_MIS_AUTO;
			else if (!strcmp(val, "power"))
				a->opt.mis = AJAR_MIS_POWER;
			else if (!strcmp(val, "balance"))
				a->opt.mis = AJAR_MIS_BALANCE;
			else
				rc = args_usage_error("--mis: '%s' is not auto, power or balance", val);
		}
		else /* --seed */
			rc = parse_u32(name, val, 0, UINT32_MAX, &a->opt.seed);
		if (rc != EXIT_OK)
			return rc;
		static const struct {
			const char *name;
			unsigned bit;
		} bits[] = {{"--size", GIVEN_SIZE},	    {"--integrator", GIVEN_INTEGRATOR},
			    {"--max-depth", GIVEN_MAX_DEPTH}, {"--min-depth", GIVEN_MIN_DEPTH},
			    {"--seed", GIVEN_SEED},	    {"--mis", GIVEN_MIS},
			    {"--strategy-len", GIVEN_STRATEGY_LEN}, {"--spp", GIVEN_SPP},
			    {"--time", GIVEN_TIME}, {"--aov", GIVEN_AOV}, {"--portals", GIVEN_PORTALS},
			    {"--noise", GIVEN_NOISE}};
		for (size_t b = 0; b < sizeof bits / sizeof bits[0]; b++)
			if (!strcmp(name, bits[b].name))
				a->given |= bits[b].bit;
	}
	if (!a->scene)
		return args_usage_error("no scene given");
	if (check_scene_options(&a->sc) != EXIT_OK)
		return EXIT_USAGE;
	if (!a->exr)
		return args_usage_error("no output given (-o OUT.exr)");
	if (a->png && strcmp(a->png, a->exr) == 0)
		return args_usage_error("--png: '%s' is also the EXR output", a->png);
	const char *ckpt = a->checkpoint ? a->checkpoint : a->resume;
	if (ckpt && (!strcmp(ckpt, a->exr) || (a->png && !strcmp(ckpt, a->png)) ||
		     (a->strategies && !strcmp(ckpt, a->strategies))))
		return args_usage_error("%s: '%s' is also an image output", a->checkpoint ? "--checkpoint" : "--resume",
					ckpt);
	if (a->checkpoint_every > 0 && !ckpt)
		return args_usage_error("--checkpoint-every needs --checkpoint FILE or --resume FILE");
	if (!(a->checkpoint_every > 0))
		a->checkpoint_every = 60;
	if (a->strategies) {
		a->opt.strategy_len = strategy_len ? strategy_len : 4;
		if (!strcmp(a->strategies, a->exr) || (a->png && !strcmp(a->strategies, a->png)))
			return args_usage_error("--strategies: '%s' is also another output", a->strategies);
	} else if (strategy_len || a->opt.strategy_unweighted) {
		return args_usage_error("%s needs --strategies OUT.exr",
					strategy_len ? "--strategy-len" : "--unweighted");
	}
	/* 64 samples unless only a time limit or a noise target was asked for. */
	if (!spp_given)
		a->opt.spp = time_given || noise_given ? 0 : 64;
	if (!time_given)
		a->opt.time_limit = 0;
	return EXIT_OK;
}
