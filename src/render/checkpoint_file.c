/* checkpoint_file.c — the checkpoint file (checkpoint_file.h).
 *
 * Layout, native byte order (little-endian on every host Ajar runs on):
 *   "AJARCKPT", u32 format, char version[16], u64 scene_hash, params_hash,
 *   char scene[256], u32 width height integrator max_depth min_depth seed
 *   mis strategy_len strategy_unweighted spp aov portals, f64 time_limit noise elapsed,
 *   u32 nranges, u32 sections, u64 nfilm[sections], u64 file size,
 *   then nranges (u32 first, u32 count), the films as i64, and a CRC-32 of
 *   everything before it. The size in the header tells a truncated file
 *   from a corrupted one before any film is read. */
#include "render/checkpoint_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "core/error.h"
#include "image/exr.h"

#define CKPT_MAGIC "AJARCKPT"
#define CKPT_FORMAT 2u
#define CKPT_OPTIONS 12
#define HEADER_BYTES (8 + 4 + 16 + 16 + 256 + 4 * CKPT_OPTIONS + 24 + 8 + 8 * CKPT_SECTIONS + 8)

uint64_t checkpoint_hash(uint64_t h, const void *data, size_t n)
{
	uLong crc = (uLong)(h >> 32), adl = (uLong)(h & 0xffffffffu);
	if (h == 0) {
		crc = crc32(0L, Z_NULL, 0);
		adl = adler32(0L, Z_NULL, 0);
	}
	const Bytef *p = data;
	while (n > 0) {
		uInt k = n > (1u << 30) ? (1u << 30) : (uInt)n;
		crc = crc32(crc, p, k);
		adl = adler32(adl, p, k);
		p += k;
		n -= k;
	}
	return (uint64_t)crc << 32 | (uint64_t)adl;
}

/* ---- Writing --------------------------------------------------------------- */

typedef struct {
	const char *path;
	int fd;
	uLong crc;
	ajar_status st;
	unsigned char buf[1 << 16];
	size_t len;
} Writer;

static void w_flush(Writer *w)
{
	if (w->st == AJAR_OK && w->len)
		w->st = image_write_all(w->path, w->fd, w->buf, w->len);
	w->len = 0;
}

static void w_put(Writer *w, const void *data, size_t n)
{
	const unsigned char *p = data;
	while (n > 0 && w->st == AJAR_OK) {
		size_t k = sizeof w->buf - w->len;
		if (k > n)
			k = n;
		memcpy(w->buf + w->len, p, k);
		w->crc = crc32(w->crc, p, (uInt)k);
		w->len += k;
		p += k;
		n -= k;
		if (w->len == sizeof w->buf)
			w_flush(w);
	}
}

static void w_u32(Writer *w, uint32_t v) { w_put(w, &v, sizeof v); }
static void w_u64(Writer *w, uint64_t v) { w_put(w, &v, sizeof v); }
static void w_f64(Writer *w, double v) { w_put(w, &v, sizeof v); }

static uint64_t file_size(const Checkpoint *c)
{
	uint64_t n = HEADER_BYTES + 8ull * c->nranges + 4;
	for (int s = 0; s < CKPT_SECTIONS; s++)
		n += 8 * c->nfilm[s];
	return n;
}

ajar_status checkpoint_write(const char *path, const Checkpoint *c)
{
	Writer *w = calloc(1, sizeof *w);
	if (!w)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	char *tmp;
	ajar_status st = image_tmp_open(path, &tmp, &w->fd);
	if (st != AJAR_OK) {
		free(w);
		return st;
	}
	w->path = path;
	w->crc = crc32(0L, Z_NULL, 0);
	char version[16] = {0}, scene[256] = {0};
	snprintf(version, sizeof version, "%s", c->version);
	snprintf(scene, sizeof scene, "%s", c->scene);
	w_put(w, CKPT_MAGIC, 8);
	w_u32(w, CKPT_FORMAT);
	w_put(w, version, sizeof version);
	w_u64(w, c->scene_hash);
	w_u64(w, c->params_hash);
	w_put(w, scene, sizeof scene);
	const uint32_t opts[CKPT_OPTIONS] = {c->width,	  c->height, c->integrator,	    c->max_depth,
					     c->min_depth, c->seed,	 c->mis,		    c->strategy_len,
					     c->strategy_unweighted, c->spp, c->aov, c->portals};
	for (int i = 0; i < CKPT_OPTIONS; i++)
		w_u32(w, opts[i]);
	w_f64(w, c->time_limit);
	w_f64(w, c->noise);
	w_f64(w, c->elapsed);
	w_u32(w, c->nranges);
	w_u32(w, CKPT_SECTIONS);
	for (int s = 0; s < CKPT_SECTIONS; s++)
		w_u64(w, c->nfilm[s]);
	w_u64(w, file_size(c));
	for (uint32_t i = 0; i < c->nranges; i++) {
		w_u32(w, c->ranges[i].first);
		w_u32(w, c->ranges[i].count);
	}
	for (int s = 0; s < CKPT_SECTIONS; s++)
		w_put(w, c->film[s], 8 * c->nfilm[s]);
	uint32_t crc = (uint32_t)w->crc;
	w_put(w, &crc, sizeof crc);
	w_flush(w);
	st = w->st;
	/* On disk before the rename, so a crash leaves the old or the new file. */
	if (st == AJAR_OK && fsync(w->fd) != 0)
		st = err_set(AJAR_ERROR_IO, "%s: cannot write file: %s", path, strerror(errno));
	st = image_tmp_finish(path, tmp, w->fd, st);
	free(w);
	return st;
}

/* ---- Reading --------------------------------------------------------------- */

typedef struct {
	FILE *f;
	uLong crc;
	int short_read;
} Reader;

static void r_get(Reader *r, void *dst, size_t n)
{
	if (r->short_read)
		return;
	if (fread(dst, 1, n, r->f) != n) {
		r->short_read = 1;
		memset(dst, 0, n);
		return;
	}
	unsigned char *p = dst;
	for (size_t off = 0; off < n;) {
		uInt k = n - off > (1u << 30) ? (1u << 30) : (uInt)(n - off);
		r->crc = crc32(r->crc, p + off, k);
		off += k;
	}
}

static uint32_t r_u32(Reader *r)
{
	uint32_t v;
	r_get(r, &v, sizeof v);
	return v;
}

static uint64_t r_u64(Reader *r)
{
	uint64_t v;
	r_get(r, &v, sizeof v);
	return v;
}

static double r_f64(Reader *r)
{
	double v;
	r_get(r, &v, sizeof v);
	return v;
}

void checkpoint_free(Checkpoint *c)
{
	free(c->ranges);
	for (int s = 0; s < CKPT_SECTIONS; s++)
		free(c->film[s]);
	memset(c, 0, sizeof *c);
}

static ajar_status read_body(const char *path, Reader *r, Checkpoint *c, uint64_t size, uint64_t have)
{
	if (have < size)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: checkpoint is truncated (%llu of its %llu bytes); it cannot be resumed", path,
			       (unsigned long long)have, (unsigned long long)size);
	if (have > size)
		return err_set(AJAR_ERROR_BAD_INPUT,
			       "%s: checkpoint is corrupted (%llu bytes, its header says %llu)", path,
			       (unsigned long long)have, (unsigned long long)size);
	c->ranges = malloc(sizeof *c->ranges * (c->nranges ? c->nranges : 1));
	if (!c->ranges)
		return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	for (uint32_t i = 0; i < c->nranges; i++) {
		c->ranges[i].first = r_u32(r);
		c->ranges[i].count = r_u32(r);
	}
	for (int s = 0; s < CKPT_SECTIONS; s++) {
		c->film[s] = malloc(8 * (c->nfilm[s] ? c->nfilm[s] : 1));
		if (!c->film[s])
			return err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory for the checkpoint's film", path);
		r_get(r, c->film[s], 8 * c->nfilm[s]);
	}
	uint32_t want = (uint32_t)r->crc, crc = r_u32(r);
	if (r->short_read)
		return err_set(AJAR_ERROR_IO, "%s: cannot read checkpoint: %s", path,
			       ferror(r->f) ? strerror(errno) : "the file shrank while it was read");
	if (crc != want)
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is corrupted (checksum mismatch); it cannot be resumed",
			       path);
	/* Ranges sorted and disjoint, as the writer leaves them. */
	for (uint32_t i = 0; i < c->nranges; i++) {
		const SampleRange *g = &c->ranges[i];
		if (g->count == 0 || g->first > UINT32_MAX - g->count ||
		    (i > 0 && g->first < c->ranges[i - 1].first + c->ranges[i - 1].count))
			return err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is corrupted (sample ranges)", path);
	}
	return AJAR_OK;
}

ajar_status checkpoint_read(const char *path, Checkpoint *c, int header_only)
{
	memset(c, 0, sizeof *c);
	Reader r = {fopen(path, "rb"), crc32(0L, Z_NULL, 0), 0};
	if (!r.f)
		return err_set(AJAR_ERROR_IO, "%s: cannot open checkpoint: %s", path, strerror(errno));
	struct stat sb;
	uint64_t have = fstat(fileno(r.f), &sb) == 0 ? (uint64_t)sb.st_size : 0;
	ajar_status st = AJAR_OK;
	char magic[8];
	uint32_t format = 0, opts[CKPT_OPTIONS], sections;
	uint64_t size = 0;
	r_get(&r, magic, sizeof magic);
	if (r.short_read || memcmp(magic, CKPT_MAGIC, 8) != 0) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: not an Ajar checkpoint", path);
		goto out;
	}
	format = r_u32(&r);
	r_get(&r, c->version, sizeof c->version);
	c->version[sizeof c->version - 1] = '\0';
	if (r.short_read) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is truncated (%llu bytes); it cannot be resumed", path,
			     (unsigned long long)have);
		goto out;
	}
	if (format != CKPT_FORMAT || strcmp(c->version, AJAR_VERSION_STRING) != 0) {
		st = err_set(AJAR_ERROR_BAD_INPUT,
			     "%s: checkpoint made by Ajar %s (format %u); this is Ajar %s (format %u), which cannot "
			     "resume it bit for bit",
			     path, c->version, format, AJAR_VERSION_STRING, CKPT_FORMAT);
		goto out;
	}
	c->scene_hash = r_u64(&r);
	c->params_hash = r_u64(&r);
	r_get(&r, c->scene, sizeof c->scene);
	c->scene[sizeof c->scene - 1] = '\0';
	for (int i = 0; i < CKPT_OPTIONS; i++)
		opts[i] = r_u32(&r);
	c->width = opts[0];
	c->height = opts[1];
	c->integrator = opts[2];
	c->max_depth = opts[3];
	c->min_depth = opts[4];
	c->seed = opts[5];
	c->mis = opts[6];
	c->strategy_len = opts[7];
	c->strategy_unweighted = opts[8];
	c->spp = opts[9];
	c->aov = opts[10];
	c->portals = opts[11];
	c->time_limit = r_f64(&r);
	c->noise = r_f64(&r);
	c->elapsed = r_f64(&r);
	c->nranges = r_u32(&r);
	sections = r_u32(&r);
	for (int s = 0; s < CKPT_SECTIONS; s++)
		c->nfilm[s] = r_u64(&r);
	size = r_u64(&r);
	if (r.short_read) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is truncated (%llu bytes); it cannot be resumed", path,
			     (unsigned long long)have);
		goto out;
	}
	/* A header whose own numbers disagree is corrupted, whatever the size. */
	uint64_t npix = (uint64_t)c->width * c->height;
	if (sections != CKPT_SECTIONS || npix == 0 || c->nfilm[CKPT_ACCUM] != 3 * npix ||
	    c->nfilm[CKPT_SPLAT] % (3 * npix) != 0 || c->nfilm[CKPT_AOV] % npix != 0 ||
	    c->nfilm[CKPT_SPLAT] > 3 * npix * 64 || c->nfilm[CKPT_AOV] > npix * 64 || size != file_size(c)) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: checkpoint is corrupted (inconsistent header)", path);
		goto out;
	}
	if (!header_only)
		st = read_body(path, &r, c, size, have);
	else if (have < size)
		st = err_set(AJAR_ERROR_BAD_INPUT,
			     "%s: checkpoint is truncated (%llu of its %llu bytes); it cannot be resumed", path,
			     (unsigned long long)have, (unsigned long long)size);
out:
	fclose(r.f);
	if (st != AJAR_OK)
		checkpoint_free(c);
	return st;
}
