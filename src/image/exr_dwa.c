/* exr_dwa.c — our own decoder of OpenEXR's DWAA and DWAB compression,
 * which OpenEXR 3.1's C Core (Debian 12) reads but cannot decompress.
 * Blender's and Poly Haven's sky HDRIs are DWAB. exr.c sets
 * exr_dwa_decompress as the Core decode pipeline's decompress step: Core
 * reads the chunk, this turns its bytes into the chunk's uncompressed
 * layout (per scanline, per channel, little-endian samples), and Core's own
 * unpacking converts that to the caller's floats.
 *
 * The format, as OpenEXR's DwaCompressor (C++, 3.1) writes and reads it:
 *   - 88-byte chunk header: eleven little-endian u64 (version, the sizes of
 *     the four compressed sections, uncompressed sizes and value counts,
 *     and how the AC values are coded: 0 Huffman, 1 zlib);
 *   - version 2: a u16-sized list of channel rules (name suffix, pixel
 *     type -> scheme, RGB triplet index); older versions use fixed rules;
 *   - the sections: "unknown" channels (zlib, lossless), the lossy
 *     channels' AC values (OpenEXR's Huffman coder or zlib), their DC values
 *     (zlib with OpenEXR ZIP's byte predictor and interleave), and the RLE
 *     channels (alpha: zlib, then byte run-lengths, in byte planes);
 *   - lossy channels are 8x8 blocks of half DCT coefficients in zig-zag
 *     order, AC run-length coded (0xff00 ends a block, 0xffNN skips NN
 *     zeros), of values stored through a nonlinear curve: decoding is the
 *     inverse DCT, Y'CbCr -> R'G'B' for a channel triplet, rounding to half
 *     and a table back to linear half.
 * Results must equal the C++ library bit for bit. On the CPUs it runs on
 * (AVX, F16C) that library does the inverse DCT in AVX assembly whose
 * sums are associated differently from its scalar C fallback; float
 * addition is not associative, so the DCT below follows the AVX order of
 * operations (and skips the terms it skips for trailing zero rows). The
 * build uses -ffp-contract=off, so no step is fused.
 *
 * Every size and count read from the file is checked against the buffer it
 * describes; a chunk that does not fit is refused with a message, never
 * read past. */
#include "image/exr.h"
#include "image/exr_huf.h"

#include <limits.h>
#include <math.h>
#include <openexr.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <zlib.h>

_Static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "samples are written in host order, which must be EXR's");

/* ---- Half floats ---------------------------------------------------------- */

static float half_bits_to_float(uint16_t h)
{
	uint32_t sign = (uint32_t)(h & 0x8000u) << 16, e = (h >> 10) & 31u, m = h & 0x3ffu, u;
	if (e == 0) {
		if (m == 0) {
			u = sign;
		} else { /* subnormal: normalise */
			int k = 0;
			while (!(m & 0x400u)) {
				m <<= 1;
				k++;
			}
			u = sign | ((uint32_t)(113 - k) << 23) | ((m & 0x3ffu) << 13);
		}
	} else if (e == 31) {
		u = sign | 0x7f800000u | (m << 13);
	} else {
		u = sign | ((e + 112u) << 23) | (m << 13);
	}
	float f;
	memcpy(&f, &u, sizeof f);
	return f;
}

/* Round to nearest even. A NaN keeps its top payload bits; `quiet_nan`
 * picks how an otherwise-empty payload is kept a NaN: the hardware
 * conversion (vcvtps2ph, which the C++ library uses for whole blocks) sets
 * the quiet bit, Imath's software one (its constant-block path) sets bit 0. */
static inline uint16_t float_to_half(float f, int quiet_nan)
{
	uint32_t v;
	memcpy(&v, &f, sizeof v);
	uint32_t a = v & 0x7fffffffu;
	uint16_t sign = (uint16_t)((v >> 16) & 0x8000u);
	if (a >= 0x7f800000u) {
		if (a == 0x7f800000u)
			return sign | 0x7c00u;
		uint16_t m = (uint16_t)((a & 0x7fffffu) >> 13);
		return sign | 0x7c00u | (quiet_nan ? (m | 0x200u) : (m ? m : 1u));
	}
	if (a >= 0x38800000u) { /* normal half, or overflow to infinity */
		if (a > 0x477fefffu)
			return sign | 0x7c00u;
		a -= 0x38000000u;
		return sign | (uint16_t)((a + 0x0fffu + ((a >> 13) & 1u)) >> 13);
	}
	if (a < 0x33000001u) /* at most half the smallest subnormal: zero */
		return sign;
	uint32_t e = a >> 23, shift = 0x7eu - e, m = 0x800000u | (a & 0x7fffffu), rest = m << (32 - shift);
	uint16_t h = sign | (uint16_t)(m >> shift);
	if (rest > 0x80000000u || (rest == 0x80000000u && (h & 1u)))
		h++;
	return h;
}

/* ---- The nonlinear -> linear table ---------------------------------------- */

/* DWA stores lossy values through a curve that is x^(1/2.2) up to 1 and
 * logarithmic above; the table maps each stored half back to linear. It is
 * computed as OpenEXR's generator computed the table it ships (float powf,
 * e^2.2 rounded to float); test_exr checks it against that table's hash.
 * Infinities and NaNs map to 0. */
static uint16_t dwa_to_linear[65536];
static float half_float[65536]; /* every half as a float, for speed */
static pthread_once_t dwa_table_once = PTHREAD_ONCE_INIT;

static void dwa_table_init(void)
{
	for (uint32_t i = 0; i < 65536; i++)
		half_float[i] = half_bits_to_float((uint16_t)i);
	const float log_base = (float)pow(2.7182818, 2.2);
	dwa_to_linear[0] = 0;
	for (uint32_t i = 1; i < 65536; i++) {
		if ((i & 0x7c00u) == 0x7c00u) {
			dwa_to_linear[i] = 0;
			continue;
		}
		float h = half_float[i], sign = h < 0.0f ? -1.0f : 1.0f, a = fabsf(h);
		float z = a <= 1.0f ? sign * powf(a, 2.2f) : sign * powf(log_base, (float)((double)a - 1.0));
		dwa_to_linear[i] = float_to_half(z, 0);
	}
}

const uint16_t *exr_dwa_to_linear_table(void)
{
	pthread_once(&dwa_table_once, dwa_table_init);
	return dwa_to_linear;
}

/* Valid once exr_dwa_to_linear_table() has run. */
static inline float half_to_float(uint16_t h)
{
	return half_float[h];
}

/* ---- Errors --------------------------------------------------------------- */

typedef struct {
	char *msg; /* EXR_DWA_MSG bytes, or NULL */
} DwaErr;

static exr_result_t dwa_fail(DwaErr *err, exr_result_t rv, const char *fmt, ...)
{
	if (err->msg) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err->msg, EXR_DWA_MSG, fmt, ap);
		va_end(ap);
	}
	return rv;
}

#define CORRUPT(...) dwa_fail(err, EXR_ERR_CORRUPT_CHUNK, "DWA chunk: " __VA_ARGS__)

static uint64_t rd_u64(const uint8_t *p)
{
	uint64_t v = 0;
	for (int i = 7; i >= 0; i--)
		v = (v << 8) | p[i];
	return v;
}

/* ---- zlib, RLE and ZIP's predictor ----------------------------------------- */

/* Inflates exactly `nout` bytes (a section that says its size). */
static exr_result_t dwa_inflate(const uint8_t *in, uint64_t n, uint8_t *out, uint64_t nout, const char *what,
				DwaErr *err)
{
	uLongf got = (uLongf)nout;
	if (n > ULONG_MAX || nout > ULONG_MAX)
		return CORRUPT("%s section too large", what);
	int z = uncompress(out, &got, in, (uLong)n);
	if (z == Z_MEM_ERROR)
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory inflating DWA %s data", what);
	if (z != Z_OK || got != nout)
		return CORRUPT("%s data does not inflate to its %llu bytes", what, (unsigned long long)nout);
	return EXR_ERR_SUCCESS;
}

/* OpenEXR's byte RLE: a negative count -n is n literal bytes, a count
 * n >= 0 repeats the next byte n + 1 times. Must fill `nout` exactly. */
static exr_result_t rle_expand(const uint8_t *in, size_t n, uint8_t *out, size_t nout, DwaErr *err)
{
	size_t i = 0, o = 0;
	while (i < n) {
		int count = (int8_t)in[i++];
		if (count < 0) {
			size_t k = (size_t)(-count);
			if (k > n - i || k > nout - o)
				return CORRUPT("RLE data runs past its buffer");
			memcpy(out + o, in + i, k);
			i += k;
			o += k;
		} else {
			size_t k = (size_t)count + 1;
			if (i >= n || k > nout - o)
				return CORRUPT("RLE data runs past its buffer");
			memset(out + o, in[i++], k);
			o += k;
		}
	}
	return o == nout ? EXR_ERR_SUCCESS : CORRUPT("RLE data gives %zu bytes, not %zu", o, nout);
}

/* ---- Inverse DCT ------------------------------------------------------------ */

/* The constants, as the C++ library's AVX code writes them (double literals
 * rounded to float). */
static const float A_ = 3.535536e-01, B_ = 4.903927e-01, C_ = 4.619398e-01, D_ = 4.157349e-01,
		   E_ = 2.777855e-01, F_ = 1.913422e-01, G_ = 9.754573e-02;

/* Zig-zag index of each coefficient in row-major order. */
static const uint8_t zigzag[64] = {
	0,  1,	5,  6,	14, 15, 27, 28, 2,  4,	7,  13, 16, 26, 29, 42, 3,  8,	12, 17, 25, 30,
	41, 43, 9,  11, 18, 24, 31, 40, 44, 53, 10, 19, 23, 32, 39, 45, 52, 54, 20, 22, 33, 38,
	46, 51, 55, 60, 21, 34, 37, 47, 50, 56, 59, 61, 35, 36, 48, 49, 57, 58, 62, 63,
};

/* One row, in place: the even inputs through M1, the odd through M2, each
 * as (x0 m0 + x1 m1) + (x2 m2 + x3 m3), then sum and difference. */
static void idct_row(float *r)
{
	static const float m1[4][4] = {{A_, A_, A_, A_}, {C_, F_, -F_, -C_}, {A_, -A_, -A_, A_}, {F_, -C_, C_, -F_}};
	static const float m2[4][4] = {{B_, D_, E_, G_}, {D_, -G_, -B_, -E_}, {E_, -B_, G_, D_}, {G_, -E_, D_, -B_}};
	float ev[4], od[4];
	for (int k = 0; k < 4; k++) {
		ev[k] = (r[0] * m1[0][k] + r[2] * m1[1][k]) + (r[4] * m1[2][k] + r[6] * m1[3][k]);
		od[k] = (r[1] * m2[0][k] + r[3] * m2[1][k]) + (r[5] * m2[2][k] + r[7] * m2[3][k]);
	}
	for (int k = 0; k < 4; k++) {
		r[k] = ev[k] + od[k];
		r[7 - k] = ev[k] - od[k];
	}
}

/* Inverse 8x8 DCT in place, knowing rows n..7 of the input are zero
 * (1 <= n <= 8): the terms of those rows are left out, not added as
 * zeros, as the C++ library's specialised code does (it matters for the
 * sign of zero results). */
static void idct8x8(float *d, int n)
{
	for (int r = 0; r < n; r++)
		idct_row(d + 8 * r);
	if (n == 1) {
		for (int i = 8; i < 64; i++)
			d[i] = d[i & 7] * A_;
		for (int i = 0; i < 8; i++)
			d[i] *= A_;
		return;
	}
	for (int x = 0; x < 8; x++) {
		float R[8];
		for (int r = 0; r < n; r++)
			R[r] = d[8 * r + x];
		/* Odd rows. */
		float o0 = B_ * R[1], o1 = D_ * R[1], o2 = E_ * R[1], o3 = G_ * R[1];
		if (n > 3) {
			o0 = o0 + D_ * R[3];
			float w = G_ * R[3];
			if (n > 5) {
				float u = E_ * R[5];
				if (n > 7)
					u = u + G_ * R[7];
				o0 = o0 + u;
				w = B_ * R[5] + w;
			}
			o1 = o1 - w;
			if (n > 7)
				o1 = o1 - E_ * R[7];
			o2 = o2 - B_ * R[3];
			if (n > 5)
				o2 = o2 + G_ * R[5];
			if (n > 7)
				o2 = o2 + D_ * R[7];
			if (n > 5)
				o3 = D_ * R[5] + o3;
			float v = E_ * R[3];
			if (n > 7)
				v = B_ * R[7] + v;
			o3 = o3 - v;
		}
		/* Even rows. */
		float p = A_ * R[0], q = p;
		if (n > 4) {
			float a4 = A_ * R[4];
			p = p + a4;
			q = q - a4;
		}
		float e0 = p, e3 = p, e1 = q, e2 = q;
		if (n > 2) {
			float s = C_ * R[2], t = F_ * R[2];
			if (n > 6) {
				s = s + F_ * R[6];
				t = t - C_ * R[6];
			}
			e0 = p + s;
			e3 = p - s;
			e1 = q + t;
			e2 = q - t;
		}
		d[x] = e0 + o0;
		d[8 + x] = e1 + o1;
		d[16 + x] = e2 + o2;
		d[24 + x] = e3 + o3;
		d[32 + x] = e3 - o3;
		d[40 + x] = e2 - o2;
		d[48 + x] = e1 - o1;
		d[56 + x] = e0 - o0;
	}
}

/* Y'CbCr -> R'G'B' (Rec. 709), in the C++ library's order of operations. */
static void csc709_inverse(float *y, float *cb, float *cr)
{
	float Y = *y, Cb = *cb, Cr = *cr;
	*y = Y + Cr * 1.5747f;
	*cb = (Cb * -0.1873f + Y) + Cr * -0.4682f;
	*cr = 1.8556f * Cb + Y;
}

/* ---- Channels and rules ----------------------------------------------------- */

enum { SCHEME_UNKNOWN, SCHEME_LOSSY_DCT, SCHEME_RLE, SCHEME_COUNT };

typedef struct {
	char suffix[130];
	int scheme, csc, nocase, type;
} DwaRule;

typedef struct {
	const char *name;
	int type, size; /* EXR_PIXEL_*, bytes per sample */
	int32_t width, height, ys;
	int linear;
	int scheme;
	size_t *rows; /* byte offset of each of its rows in the output */
} DwaChannel;

static size_t dwa_default_rules(DwaRule *r, int legacy)
{
	static const struct {
		const char *s;
		int scheme, csc;
	} std_rules[] = {{"R", 1, 0}, {"G", 1, 1}, {"B", 1, 2}, {"Y", 1, -1}, {"BY", 1, -1}, {"RY", 1, -1}, {"A", 2, -1}},
	  old_rules[] = {{"r", 1, 0},  {"red", 1, 0},  {"g", 1, 1},  {"grn", 1, 1}, {"green", 1, 1},
			 {"b", 1, 2},  {"blu", 1, 2},  {"blue", 1, 2}, {"y", 1, -1}, {"by", 1, -1},
			 {"ry", 1, -1}, {"a", 2, -1}};
	size_t n = 0, count = legacy ? sizeof old_rules / sizeof old_rules[0] : sizeof std_rules / sizeof std_rules[0];
	for (size_t i = 0; i < count; i++) {
		const char *s = legacy ? old_rules[i].s : std_rules[i].s;
		int scheme = legacy ? old_rules[i].scheme : std_rules[i].scheme;
		int csc = legacy ? old_rules[i].csc : std_rules[i].csc;
		/* Lossy rules for half and float; alpha for uint, half, float. */
		static const int lossy_types[] = {EXR_PIXEL_HALF, EXR_PIXEL_FLOAT};
		static const int rle_types[] = {EXR_PIXEL_UINT, EXR_PIXEL_HALF, EXR_PIXEL_FLOAT};
		const int *types = scheme == SCHEME_RLE ? rle_types : lossy_types;
		int nt = scheme == SCHEME_RLE ? 3 : 2;
		for (int k = 0; k < nt; k++) {
			snprintf(r[n].suffix, sizeof r[n].suffix, "%s", s);
			r[n].scheme = scheme;
			r[n].csc = csc;
			r[n].nocase = legacy;
			r[n].type = types[k];
			n++;
		}
	}
	return n;
}

static int rule_matches(const DwaRule *r, const char *suffix, int type)
{
	if (r->type != type)
		return 0;
	return r->nocase ? strcasecmp(suffix, r->suffix) == 0 : strcmp(suffix, r->suffix) == 0;
}

/* ---- Lossy DCT channels ----------------------------------------------------- */

typedef struct {
	const uint16_t *ac, *ac_end;
	const uint16_t *dc, *dc_end;
} Coeffs;

/* Fills the zig-zag block's AC values from the run-length stream; returns
 * the zig-zag index of the last nonzero one (0: DC only), or -1 if the
 * stream ends first. */
static int unrle_ac(Coeffs *co, uint16_t *zig)
{
	int last = 0;
	for (int i = 1; i < 64;) {
		if (co->ac == co->ac_end)
			return -1;
		uint16_t v = *co->ac++;
		if (v == 0xff00u) {
			break;
		} else if ((v >> 8) == 0xffu) {
			i += v & 0xffu;
		} else {
			zig[i] = v;
			last = i++;
		}
	}
	return last;
}


/* Decodes 1 channel, or 3 (an R, G, B triplet coded as Y'CbCr), of
 * blocks; their DC values are consecutive planes. */
static exr_result_t dwa_lossy(DwaChannel *const *ch, int ncomp, Coeffs *co, const uint16_t *to_linear, uint8_t *out,
			      DwaErr *err)
{
	const int32_t w = ch[0]->width, h = ch[0]->height;
	const int32_t bx_n = (w + 7) / 8, by_n = (h + 7) / 8;
	const size_t nblocks = (size_t)bx_n * (size_t)by_n;
	if (nblocks == 0)
		return EXR_ERR_SUCCESS;
	if ((size_t)(co->dc_end - co->dc) < nblocks * (size_t)ncomp)
		return CORRUPT("fewer DC values than blocks");
	const uint16_t *dc[3];
	for (int c = 0; c < ncomp; c++)
		dc[c] = co->dc + (size_t)c * nblocks;
	co->dc += nblocks * (size_t)ncomp;
	uint16_t *row_block = malloc(((size_t)ncomp * (size_t)bx_n * 64 + (size_t)w) * sizeof *row_block);
	uint16_t *line = row_block ? row_block + (size_t)ncomp * (size_t)bx_n * 64 : NULL; /* one row */
	if (!row_block)
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for a row of DCT blocks");
	float dct[3][64];
	for (int32_t by = 0; by < by_n; by++) {
		for (int32_t bx = 0; bx < bx_n; bx++) {
			int constant = 1;
			for (int c = 0; c < ncomp; c++) {
				uint16_t zig[64] = {0};
				zig[0] = *dc[c]++;
				int last = unrle_ac(co, zig);
				if (last < 0) {
					free(row_block);
					return CORRUPT("fewer AC values than blocks need");
				}
				if (last == 0) {
					float v = half_to_float(zig[0]) * 3.535536e-01f * 3.535536e-01f;
					for (int i = 0; i < 64; i++)
						dct[c][i] = v;
					continue;
				}
				constant = 0;
				for (int i = 0; i < 64; i++)
					dct[c][i] = half_to_float(zig[zigzag[i]]);
				/* Rows below the last nonzero coefficient's row
				 * are zero: row r starts at zig-zag index
				 * 2, 3, 9, 10, 20, 21, 35 for r = 1..7. */
				static const int row_start[7] = {2, 3, 9, 10, 20, 21, 35};
				int rows = 1;
				while (rows < 8 && last >= row_start[rows - 1])
					rows++;
				idct8x8(dct[c], rows);
			}
			uint16_t *dst[3];
			for (int c = 0; c < ncomp; c++)
				dst[c] = row_block + ((size_t)c * (size_t)bx_n + (size_t)bx) * 64;
			if (constant) {
				if (ncomp == 3)
					csc709_inverse(&dct[0][0], &dct[1][0], &dct[2][0]);
				for (int c = 0; c < ncomp; c++) {
					uint16_t v = float_to_half(dct[c][0], 0);
					for (int i = 0; i < 64; i++)
						dst[c][i] = v;
				}
			} else {
				if (ncomp == 3)
					for (int i = 0; i < 64; i++)
						csc709_inverse(&dct[0][i], &dct[1][i], &dct[2][i]);
				for (int c = 0; c < ncomp; c++)
					for (int i = 0; i < 64; i++)
						dst[c][i] = float_to_half(dct[c][i], 1);
			}
		}
		/* Unblock this row of blocks into the channels' rows. */
		int32_t y_n = by == by_n - 1 ? h - by * 8 : 8;
		for (int c = 0; c < ncomp; c++) {
			const DwaChannel *cd = ch[c];
			for (int32_t yy = 0; yy < y_n; yy++) {
				uint8_t *dst = out + cd->rows[by * 8 + yy];
				const uint16_t *src = row_block + (size_t)c * (size_t)bx_n * 64 + (size_t)yy * 8;
				for (int32_t x = 0; x < w; x++)
					line[x] = src[(size_t)(x >> 3) * 64 + (size_t)(x & 7)];
				if (to_linear)
					for (int32_t x = 0; x < w; x++)
						line[x] = to_linear[line[x]];
				/* Little-endian half or float samples, as they are
				 * in memory on this host (asserted above). */
				if (cd->type == EXR_PIXEL_FLOAT)
					for (int32_t x = 0; x < w; x++)
						memcpy(dst + 4 * (size_t)x, &half_float[line[x]], 4);
				else
					memcpy(dst, line, 2 * (size_t)w);
			}
		}
	}
	free(row_block);
	return EXR_ERR_SUCCESS;
}

/* ---- A chunk ---------------------------------------------------------------- */

enum {
	H_VERSION,
	H_UNKNOWN_RAW,
	H_UNKNOWN_PACKED,
	H_AC_PACKED,
	H_DC_PACKED,
	H_RLE_PACKED,
	H_RLE_INFLATED,
	H_RLE_RAW,
	H_AC_COUNT,
	H_DC_COUNT,
	H_AC_CODING,
	H_COUNT
};

static int64_t floor_div(int64_t a, int64_t b)
{
	return a >= 0 ? a / b : -((-a + b - 1) / b);
}

typedef struct {
	DwaChannel *ch;
	int nch;
	DwaRule *rules;
	uint16_t *ac, *dc;
	uint8_t *unknown, *rle, *rle_raw;
	size_t *rows;
} DwaWork;

static void work_free(DwaWork *k)
{
	free(k->ch);
	free(k->rules);
	free(k->ac);
	free(k->dc);
	free(k->unknown);
	free(k->rle);
	free(k->rle_raw);
	free(k->rows);
}

static exr_result_t dwa_chunk(const exr_decode_pipeline_t *dec, const uint8_t *in, uint64_t n, uint8_t *out,
			      uint64_t nout, DwaWork *k, DwaErr *err)
{
	if (n < H_COUNT * 8)
		return CORRUPT("%llu bytes, shorter than its header", (unsigned long long)n);
	uint64_t hd[H_COUNT];
	for (int i = 0; i < H_COUNT; i++)
		hd[i] = rd_u64(in + 8 * i);
	if (hd[H_VERSION] > 2)
		return CORRUPT("version %llu (only 0..2 exist)", (unsigned long long)hd[H_VERSION]);
	const uint64_t sections[4] = {hd[H_UNKNOWN_PACKED], hd[H_AC_PACKED], hd[H_DC_PACKED], hd[H_RLE_PACKED]};
	uint64_t pos = H_COUNT * 8, total = 0;
	for (int i = 0; i < 4; i++) {
		if (sections[i] > n)
			return CORRUPT("section of %llu bytes in a chunk of %llu", (unsigned long long)sections[i],
				       (unsigned long long)n);
		total += sections[i];
	}

	/* Rules. */
	size_t nrules;
	k->rules = malloc(64 * sizeof *k->rules);
	if (!k->rules)
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA rules");
	if (hd[H_VERSION] < 2) {
		nrules = dwa_default_rules(k->rules, 1);
	} else {
		if (n - pos < 2)
			return CORRUPT("cut short before its channel rules");
		uint32_t rsize = (uint32_t)in[pos] | (uint32_t)in[pos + 1] << 8;
		if (rsize < 2 || rsize > n - pos)
			return CORRUPT("channel rules of %u bytes", rsize);
		const uint8_t *p = in + pos + 2, *end = in + pos + rsize;
		pos += rsize;
		nrules = 0;
		while (p < end) {
			const uint8_t *z = memchr(p, 0, (size_t)(end - p));
			if (!z || z - p > 128 || end - z < 3)
				return CORRUPT("malformed channel rule");
			if (nrules == 64)
				return CORRUPT("more than 64 channel rules");
			DwaRule *r = &k->rules[nrules++];
			memcpy(r->suffix, p, (size_t)(z - p) + 1);
			uint8_t v = z[1], type = z[2];
			r->csc = (v >> 4) - 1;
			r->scheme = (v >> 2) & 3;
			r->nocase = v & 1;
			r->type = type;
			if (r->csc > 2 || r->scheme >= SCHEME_COUNT || type > EXR_PIXEL_FLOAT)
				return CORRUPT("malformed channel rule");
			p = z + 3;
		}
	}
	if (total > n - pos)
		return CORRUPT("sections of %llu bytes after a %llu-byte header in a chunk of %llu",
			       (unsigned long long)total, (unsigned long long)pos, (unsigned long long)n);
	const uint8_t *sec_unknown = in + pos, *sec_ac = sec_unknown + sections[0], *sec_dc = sec_ac + sections[1],
		      *sec_rle = sec_dc + sections[2];

	/* Channels: schemes by the last matching rule; triplets by prefix. */
	k->nch = dec->channel_count;
	k->ch = calloc((size_t)k->nch, sizeof *k->ch);
	int *csc_idx = calloc((size_t)k->nch * 3 + 1, sizeof *csc_idx);
	if (!k->ch || !csc_idx) {
		free(csc_idx);
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA channels");
	}
	size_t nrows = 0;
	for (int c = 0; c < k->nch; c++) {
		const exr_coding_channel_info_t *ci = &dec->channels[c];
		DwaChannel *cd = &k->ch[c];
		cd->name = ci->channel_name;
		cd->type = ci->data_type;
		cd->size = ci->bytes_per_element;
		cd->width = ci->width;
		cd->height = ci->height;
		cd->ys = ci->y_samples > 0 ? ci->y_samples : 1;
		cd->linear = ci->p_linear;
		cd->scheme = SCHEME_UNKNOWN;
		if (cd->width < 0 || cd->height < 0 || (cd->size != 2 && cd->size != 4)) {
			free(csc_idx);
			return CORRUPT("channel %s has an unexpected layout", cd->name);
		}
		nrows += (size_t)cd->height;
		const char *dot = strrchr(cd->name, '.'), *suffix = dot ? dot + 1 : cd->name;
		for (size_t r = 0; r < nrules; r++)
			if (rule_matches(&k->rules[r], suffix, cd->type)) {
				cd->scheme = k->rules[r].scheme;
				if (k->rules[r].csc >= 0)
					csc_idx[3 * c + k->rules[r].csc] = c + 1;
			}
	}
	/* csc_idx[3 c + i] marks channel c as member i of its prefix's
	 * triplet; gather triplets keyed by the first channel with that prefix. */
	int *sets = calloc((size_t)k->nch * 3 + 1, sizeof *sets), nsets = 0;
	if (!sets) {
		free(csc_idx);
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA channels");
	}
	for (int c = 0; c < k->nch; c++) {
		const char *dot = strrchr(k->ch[c].name, '.');
		size_t plen = dot ? (size_t)(dot - k->ch[c].name) : 0;
		int first = 1;
		for (int d = 0; d < c && first; d++) {
			const char *dd = strrchr(k->ch[d].name, '.');
			size_t dlen = dd ? (size_t)(dd - k->ch[d].name) : 0;
			first = !(dlen == plen && memcmp(k->ch[d].name, k->ch[c].name, plen) == 0);
		}
		if (!first)
			continue;
		int idx[3] = {-1, -1, -1};
		for (int d = c; d < k->nch; d++) {
			const char *dd = strrchr(k->ch[d].name, '.');
			size_t dlen = dd ? (size_t)(dd - k->ch[d].name) : 0;
			if (dlen == plen && memcmp(k->ch[d].name, k->ch[c].name, plen) == 0)
				for (int i = 0; i < 3; i++)
					if (csc_idx[3 * d + i])
						idx[i] = d;
		}
		if (idx[0] < 0 || idx[1] < 0 || idx[2] < 0)
			continue;
		const DwaChannel *r = &k->ch[idx[0]], *g = &k->ch[idx[1]], *b = &k->ch[idx[2]];
		if (dec->channels[idx[0]].x_samples != dec->channels[idx[1]].x_samples ||
		    dec->channels[idx[0]].x_samples != dec->channels[idx[2]].x_samples || r->ys != g->ys || r->ys != b->ys)
			continue;
		for (int i = 0; i < 3; i++)
			sets[3 * nsets + i] = idx[i];
		nsets++;
	}
	free(csc_idx);
	/* Triplets are decoded in the order of their prefixes, as the C++
	 * library's std::map<std::string> keeps them (bytewise, a prefix of
	 * another first); the channel list's order can differ ("a.b.R" comes
	 * before "a.R" but its prefix "a.b" sorts after "a"). */
	for (int i = 1; i < nsets; i++)
		for (int j = i; j > 0; j--) {
			const char *x = k->ch[sets[3 * j]].name, *y = k->ch[sets[3 * (j - 1)]].name;
			const char *xd = strrchr(x, '.'), *yd = strrchr(y, '.');
			size_t xl = xd ? (size_t)(xd - x) : 0, yl = yd ? (size_t)(yd - y) : 0;
			int cmp = memcmp(x, y, xl < yl ? xl : yl);
			if (cmp > 0 || (cmp == 0 && xl >= yl))
				break;
			for (int q = 0; q < 3; q++) {
				int t = sets[3 * j + q];
				sets[3 * j + q] = sets[3 * (j - 1) + q];
				sets[3 * (j - 1) + q] = t;
			}
		}

	/* Where each channel's rows go: scanline by scanline, channel by
	 * channel, rows of sampled lines only. */
	k->rows = malloc((nrows + 1) * sizeof *k->rows);
	if (!k->rows) {
		free(sets);
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA rows");
	}
	size_t at = 0;
	for (int c = 0, r = 0; c < k->nch; r += k->ch[c].height, c++)
		k->ch[c].rows = k->rows + r;
	int32_t *filled = calloc((size_t)k->nch, sizeof *filled);
	if (!filled) {
		free(sets);
		return dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA rows");
	}
	for (int32_t y = 0; y < dec->chunk.height; y++)
		for (int c = 0; c < k->nch; c++) {
			DwaChannel *cd = &k->ch[c];
			int64_t ay = (int64_t)dec->chunk.start_y + y;
			if (ay - floor_div(ay, cd->ys) * cd->ys != 0)
				continue;
			if (filled[c] == cd->height) {
				free(filled);
				free(sets);
				return CORRUPT("channel %s has more lines than Core counts", cd->name);
			}
			cd->rows[filled[c]++] = at;
			at += (size_t)cd->width * (size_t)cd->size;
		}
	for (int c = 0; c < k->nch; c++)
		if (filled[c] != k->ch[c].height) {
			free(filled);
			free(sets);
			return CORRUPT("channel %s has fewer lines than Core counts", k->ch[c].name);
		}
	free(filled);
	if (at != nout) {
		free(sets);
		return CORRUPT("%zu bytes of samples, Core expects %llu", at, (unsigned long long)nout);
	}

	/* Section sizes the channels imply. */
	uint64_t unknown_bytes = 0, rle_bytes = 0, dc_max = 0;
	for (int c = 0; c < k->nch; c++) {
		const DwaChannel *cd = &k->ch[c];
		uint64_t bytes = (uint64_t)cd->width * (uint64_t)cd->height * (uint64_t)cd->size;
		if (cd->scheme == SCHEME_UNKNOWN)
			unknown_bytes += bytes;
		else if (cd->scheme == SCHEME_RLE)
			rle_bytes += bytes;
		else
			dc_max += (uint64_t)((cd->width + 7) / 8) * (uint64_t)((cd->height + 7) / 8);
	}
	exr_result_t rv = EXR_ERR_SUCCESS;
	if (hd[H_AC_COUNT] > dc_max * 63 || hd[H_DC_COUNT] > dc_max) {
		rv = CORRUPT("%llu AC and %llu DC values for %llu blocks", (unsigned long long)hd[H_AC_COUNT],
			     (unsigned long long)hd[H_DC_COUNT], (unsigned long long)dc_max);
		goto out;
	}
	if (unknown_bytes) {
		if (hd[H_UNKNOWN_RAW] != unknown_bytes) {
			rv = CORRUPT("%llu bytes of lossless channels, expected %llu",
				     (unsigned long long)hd[H_UNKNOWN_RAW], (unsigned long long)unknown_bytes);
			goto out;
		}
		k->unknown = malloc(unknown_bytes);
		if (!k->unknown) {
			rv = dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA lossless channels");
			goto out;
		}
		rv = dwa_inflate(sec_unknown, sections[0], k->unknown, unknown_bytes, "lossless-channel", err);
		if (rv)
			goto out;
	}
	if (hd[H_AC_COUNT]) {
		k->ac = malloc(hd[H_AC_COUNT] * sizeof *k->ac);
		if (!k->ac) {
			rv = dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA AC values");
			goto out;
		}
		if (hd[H_AC_CODING] == 0) {
			char why[EXR_DWA_MSG];
			rv = exr_huf_decode(sec_ac, (size_t)sections[1], k->ac, (size_t)hd[H_AC_COUNT], why);
			if (rv)
				rv = dwa_fail(err, rv, "%s%s", rv == EXR_ERR_CORRUPT_CHUNK ? "DWA chunk: " : "", why);
		} else if (hd[H_AC_CODING] == 1) {
			rv = dwa_inflate(sec_ac, sections[1], (uint8_t *)k->ac, hd[H_AC_COUNT] * 2, "AC", err);
			for (uint64_t i = 0; rv == EXR_ERR_SUCCESS && i < hd[H_AC_COUNT]; i++) {
				const uint8_t *b = (const uint8_t *)(k->ac + i);
				k->ac[i] = (uint16_t)(b[0] | b[1] << 8);
			}
		} else {
			rv = CORRUPT("AC coding %llu (only 0, Huffman, and 1, zlib, exist)",
				     (unsigned long long)hd[H_AC_CODING]);
		}
		if (rv)
			goto out;
	}
	if (hd[H_DC_COUNT]) {
		size_t nb = (size_t)hd[H_DC_COUNT] * 2;
		uint8_t *tmp = malloc(nb);
		k->dc = malloc(nb);
		if (!tmp || !k->dc) {
			free(tmp);
			rv = dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA DC values");
			goto out;
		}
		rv = dwa_inflate(sec_dc, sections[2], tmp, nb, "DC", err);
		if (rv == EXR_ERR_SUCCESS) {
			/* OpenEXR ZIP's predictor (byte deltas + 128), then the
			 * two halves interleaved back into little-endian u16. */
			for (size_t i = 1; i < nb; i++)
				tmp[i] = (uint8_t)(tmp[i - 1] + tmp[i] - 128);
			for (size_t i = 0; i < nb / 2; i++)
				k->dc[i] = (uint16_t)(tmp[i] | tmp[nb / 2 + i] << 8);
		}
		free(tmp);
		if (rv)
			goto out;
	} else if (sections[2]) {
		rv = CORRUPT("DC section without DC values");
		goto out;
	}
	if (rle_bytes) {
		if (hd[H_RLE_RAW] != rle_bytes || hd[H_RLE_INFLATED] > 2 * rle_bytes + 16) {
			rv = CORRUPT("%llu bytes of run-length channels, expected %llu",
				     (unsigned long long)hd[H_RLE_RAW], (unsigned long long)rle_bytes);
			goto out;
		}
		k->rle = malloc(hd[H_RLE_INFLATED] + 1);
		k->rle_raw = malloc(rle_bytes);
		if (!k->rle || !k->rle_raw) {
			rv = dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA run-length channels");
			goto out;
		}
		rv = dwa_inflate(sec_rle, sections[3], k->rle, hd[H_RLE_INFLATED], "run-length", err);
		if (rv == EXR_ERR_SUCCESS)
			rv = rle_expand(k->rle, (size_t)hd[H_RLE_INFLATED], k->rle_raw, (size_t)rle_bytes, err);
		if (rv)
			goto out;
	}

	/* Lossy channels: triplets first, then the rest in channel order,
	 * each consuming its AC and DC values in turn. */
	Coeffs co = {k->ac, k->ac + hd[H_AC_COUNT], k->dc, k->dc + hd[H_DC_COUNT]};
	const uint16_t *to_linear = exr_dwa_to_linear_table();
	uint8_t *done = calloc((size_t)k->nch, 1);
	if (!done) {
		rv = dwa_fail(err, EXR_ERR_OUT_OF_MEMORY, "out of memory for DWA channels");
		goto out;
	}
	for (int s = 0; s < nsets && rv == EXR_ERR_SUCCESS; s++) {
		DwaChannel *trip[3] = {&k->ch[sets[3 * s]], &k->ch[sets[3 * s + 1]], &k->ch[sets[3 * s + 2]]};
		for (int i = 0; i < 3; i++)
			if (trip[i]->scheme != SCHEME_LOSSY_DCT || trip[i]->type == EXR_PIXEL_UINT ||
			    trip[i]->width != trip[0]->width || trip[i]->height != trip[0]->height)
				rv = CORRUPT("channel %s is in an RGB triplet but not lossy", trip[i]->name);
		if (rv == EXR_ERR_SUCCESS)
			rv = dwa_lossy(trip, 3, &co, to_linear, out, err);
		for (int i = 0; i < 3; i++)
			done[sets[3 * s + i]] = 1;
	}
	const uint8_t *unk = k->unknown, *rle = k->rle_raw;
	for (int c = 0; c < k->nch && rv == EXR_ERR_SUCCESS; c++) {
		DwaChannel *cd = &k->ch[c];
		if (done[c])
			continue;
		size_t rowbytes = (size_t)cd->width * (size_t)cd->size;
		if (cd->scheme == SCHEME_LOSSY_DCT) {
			if (cd->type == EXR_PIXEL_UINT)
				rv = CORRUPT("channel %s: lossy coding of integers", cd->name);
			else
				rv = dwa_lossy(&cd, 1, &co, cd->linear ? NULL : to_linear, out, err);
		} else if (cd->scheme == SCHEME_RLE) {
			/* Byte planes: all first bytes, then all second bytes... */
			size_t plane = (size_t)cd->width * (size_t)cd->height;
			for (int32_t r = 0; r < cd->height; r++)
				for (int32_t x = 0; x < cd->width; x++)
					for (int b = 0; b < cd->size; b++)
						out[cd->rows[r] + (size_t)x * (size_t)cd->size + (size_t)b] =
							rle[(size_t)b * plane + (size_t)r * (size_t)cd->width + (size_t)x];
			rle += plane * (size_t)cd->size;
		} else {
			for (int32_t r = 0; r < cd->height; r++) {
				memcpy(out + cd->rows[r], unk, rowbytes);
				unk += rowbytes;
			}
		}
	}
	free(done);
out:
	free(sets);
	return rv;
}

int32_t exr_dwa_decompress(struct _exr_decode_pipeline *dec)
{
	DwaErr err0 = {dec->decoding_user_data}, *err = &err0;
	const uint64_t n = dec->chunk.packed_size, nout = dec->chunk.unpacked_size;
	if (n > nout)
		return CORRUPT("%llu bytes for %llu bytes of samples", (unsigned long long)n, (unsigned long long)nout);
	if (n == nout) { /* stored as is: a chunk that would not compress */
		if (dec->unpacked_buffer != dec->packed_buffer)
			memcpy(dec->unpacked_buffer, dec->packed_buffer, nout);
		return EXR_ERR_SUCCESS;
	}
	DwaWork k = {0};
	exr_result_t rv = dwa_chunk(dec, dec->packed_buffer, n, dec->unpacked_buffer, nout, &k, err);
	work_free(&k);
	return rv;
}
