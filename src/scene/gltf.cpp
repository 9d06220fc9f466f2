/* gltf.cpp — the glTF 2.0 loader: tinygltf parses the file, this file turns
 * its Model into a Scene (scene.h). The only C++ in Ajar; no exception
 * leaves it (gltf_load catches everything and returns a status).
 *
 * tinygltf is used as Debian builds it (libtinygltf.so with its file system
 * and stb_image loaders compiled in), so the header is included plainly,
 * without TINYGLTF_IMPLEMENTATION or any option that changes its classes.
 *
 * tinygltf checks JSON syntax and loads buffers and images; it does not
 * check that accessors and buffer views stay inside their data, so every
 * read here is bounds-checked, and every message names the file and the
 * element (`room.gltf: meshes[2].primitives[0]: accessors[7] (NORMAL): ...`).
 * Geometry leaves in world space: positions by the node's world matrix,
 * normals by its inverse transpose, winding reversed where it mirrors.
 * What needs no tinygltf type is C, declared in gltf_parts.h: matrices,
 * decoding, the instancing rule, the scene-folder test, the extensions. */
#include <tiny_gltf.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/input_file.h"
#include "image/texture_file.h"
#include "scene/gltf.h"
#include "scene/gltf_parts.h"
#include "scene/tangents.h"

/* gltf_parts.h's codes are glTF's, as tinygltf's are. */
static_assert(GLTF_BYTE == TINYGLTF_COMPONENT_TYPE_BYTE && GLTF_UNSIGNED_BYTE == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
		      GLTF_SHORT == TINYGLTF_COMPONENT_TYPE_SHORT &&
		      GLTF_UNSIGNED_SHORT == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
		      GLTF_UNSIGNED_INT == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && GLTF_FLOAT == TINYGLTF_COMPONENT_TYPE_FLOAT &&
		      GLTF_MODE_TRIANGLES == TINYGLTF_MODE_TRIANGLES &&
		      GLTF_MODE_TRIANGLE_STRIP == TINYGLTF_MODE_TRIANGLE_STRIP &&
		      GLTF_MODE_TRIANGLE_FAN == TINYGLTF_MODE_TRIANGLE_FAN,
	      "glTF's codes");

namespace {

namespace tg = tinygltf;

struct Loader {
	const char *file;
	std::string dir;
	tg::Model model;
	Scene *s = nullptr;
	std::vector<uint32_t> material_ids; /* glTF material -> scene material */
	int default_material = -1;
	std::vector<int> image_textures;    /* glTF image -> scene texture or -1 */
	bool allow_outside = false; /* files outside the scene's folder may be read */
	std::string root;           /* the scene's folder, symbolic links resolved */
	std::string refused;        /* the first refusal of a file the scene names */
	int instancing = GLTF_INSTANCING_AUTO;
	std::vector<uint64_t> mesh_uses; /* glTF mesh -> its copies (nodes x EXT_mesh_gpu_instancing), portals aside */
	std::vector<int> mesh_id;   /* glTF mesh -> scene mesh; -1 not loaded yet, -2 nothing to instance */
	std::vector<char> mesh_inst; /* glTF mesh -> kept once, as instances */
};

ajar_status fail(const Loader &L, ajar_status st, const char *fmt, ...) AJAR_PRINTF(3, 4);
ajar_status fail(const Loader &L, ajar_status st, const char *fmt, ...)
{
	char buf[1536];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	return err_set(st, "%s: %s", L.file, buf);
}

/* tinygltf's messages end in newlines and may hold several lines. */
std::string one_line(std::string m)
{
	while (!m.empty() && (m.back() == '\n' || m.back() == '\r'))
		m.pop_back();
	for (char &c : m)
		if (c == '\n')
			c = ';';
	return m;
}

/* ---- Files the scene names ------------------------------------------------
 * A render farm or a web service renders files other people wrote, so by
 * default every file a scene names (buffers, images, the environment image)
 * must resolve, after `..` and symbolic links, inside the scene file's
 * folder. The first refusal is kept in L.refused and becomes the load's
 * error (tinygltf itself only says "File not found" or warns). */

/* Whether `path` (which exists) lies inside L.root; sets L.refused if not.
 * `uri` is how the scene named it, for the message. */
bool confined(Loader &L, const std::string &path, const std::string &uri)
{
	if (L.allow_outside)
		return true;
	char real[PATH_MAX];
	int r = gltf_path_inside(L.root.c_str(), path.c_str(), real);
	if (r < 0)
		return false;
	bool inside = r > 0;
	if (!inside && L.refused.empty())
		L.refused = "'" + uri + "' resolves to " + real + ", outside the scene's folder " + L.root +
			    " (allow it with --allow-outside-files or ajar_load_options.allow_outside_files)";
	return inside;
}

/* tinygltf joins its base directory (or ".") and the URI; the URI again. */
std::string uri_of(const Loader &L, const std::string &joined)
{
	for (const std::string &base : {L.dir + "/", std::string("./")})
		if (joined.compare(0, base.size(), base) == 0)
			return joined.substr(base.size());
	return joined;
}

/* An absolute URI is an absolute path, not one under the base directory. */
std::string fs_expand(const std::string &joined, void *user)
{
	std::string uri = uri_of(*(const Loader *)user, joined);
	return !uri.empty() && uri[0] == '/' ? uri : joined;
}

/* Nothing is opened here (tinygltf's own FileExists opens the file, which
 * blocks on a FIFO): the name exists and is inside the folder. */
bool fs_exists(const std::string &path, void *user)
{
	Loader &L = *(Loader *)user;
	struct stat sb;
	return stat(path.c_str(), &sb) == 0 && confined(L, path, uri_of(L, path));
}

ajar_status read_fd(const char *path, int fd, uint64_t size, std::vector<unsigned char> &data);

/* Confined first, then opened as a regular file only (input_open); the
 * first refusal becomes the load's error, naming the URI. */
bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
	Loader &L = *(Loader *)user;
	std::string uri = uri_of(L, path);
	if (!confined(L, path, uri)) {
		if (err)
			*err += "outside the scene's folder\n";
		return false;
	}
	int fd;
	uint64_t size = 0;
	ajar_status st = input_open(path.c_str(), &fd, &size);
	if (st == AJAR_OK)
		st = read_fd(path.c_str(), fd, size, *out);
	if (st != AJAR_OK) {
		if (L.refused.empty())
			L.refused = "'" + uri + "': " + ajar_last_error();
		if (err)
			*err += std::string(ajar_last_error()) + "\n";
		return false;
	}
	return true;
}

/* ---- Images ----------------------------------------------------------------
 * tinygltf's own loader decodes every image from the size its header
 * claims; ours decodes through image/texture_file.c, which checks that size
 * first and refuses a file cut short, and names the image by its URI. */

/* How a message names images[i]: its URI, its buffer view or "data URI". */
std::string image_name(const tg::Image *im, int i)
{
	std::string s = "images[" + std::to_string(i) + "] (";
	if (!im->uri.empty())
		s += "'" + im->uri + "'";
	else if (im->bufferView >= 0)
		s += "bufferViews[" + std::to_string(im->bufferView) + "]";
	else
		s += "a data URI";
	return s + ")";
}

bool load_image(tg::Image *im, const int i, std::string *err, std::string *, int, int, const unsigned char *bytes,
		int size, void *user)
{
	/* tinygltf hands over an image's buffer view unchecked: one that lies
	 * past its buffer was read past the buffer's end (fuzz_gltf, ASan:
	 * heap-buffer-overflow). The model is the one being parsed. */
	const tg::Model &m = ((const Loader *)user)->model;
	if (im->bufferView >= 0) {
		size_t v = (size_t)im->bufferView;
		const tg::BufferView *bv = v < m.bufferViews.size() ? &m.bufferViews[v] : nullptr;
		size_t have = bv && bv->buffer >= 0 && (size_t)bv->buffer < m.buffers.size()
				      ? m.buffers[(size_t)bv->buffer].data.size()
				      : 0;
		if (!bv || bv->byteLength > have || bv->byteOffset > have - bv->byteLength || bv->byteLength > INT32_MAX) {
			if (err)
				*err += image_name(im, i) + ": its bufferView lies outside its buffer\n";
			return false;
		}
	}
	unsigned char *px = nullptr;
	int w = 0, h = 0, bits = 8;
	char why[256];
	if (!texture_decode(bytes, size > 0 ? (size_t)size : 0, &px, &w, &h, &bits, why, sizeof why)) {
		if (err)
			*err += image_name(im, i) + ": " + why + "\n";
		return false;
	}
	im->width = w;
	im->height = h;
	im->component = 4;
	im->bits = bits;
	im->pixel_type = bits == 16 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
	try {
		im->image.assign(px, px + (size_t)w * (size_t)h * 4 * (size_t)(bits / 8));
	} catch (...) {
		texture_free(px);
		throw;
	}
	texture_free(px);
	return true;
}

/* ---- Accessors ---------------------------------------------------------- */

int type_components(int type)
{
	switch (type) {
	case TINYGLTF_TYPE_SCALAR: return 1;
	case TINYGLTF_TYPE_VEC2: return 2;
	case TINYGLTF_TYPE_VEC3: return 3;
	case TINYGLTF_TYPE_VEC4: return 4;
	}
	return 0;
}

/* An accessor's elements, tightly packed, sparse substitution applied. */
struct Packed {
	std::vector<uint8_t> bytes;
	size_t count = 0;
	int ctype = 0, ncomp = 0;
	bool normalized = false;
};

/* Points *p at bytes [offset, offset + need) of bufferViews[v], after checking
 * that the view lies inside its buffer and the range inside the view. */
ajar_status view_range(const Loader &L, const char *what, int v, size_t offset, size_t need, const uint8_t **p)
{
	const tg::Model &m = L.model;
	if (v < 0 || (size_t)v >= m.bufferViews.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: bufferViews[%d] does not exist (%zu buffer views)", what, v,
			    m.bufferViews.size());
	const tg::BufferView &bv = m.bufferViews[(size_t)v];
	if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "bufferViews[%d]: buffers[%d] does not exist (%zu buffers)", v,
			    bv.buffer, m.buffers.size());
	size_t have = m.buffers[(size_t)bv.buffer].data.size();
	if (bv.byteLength > have || bv.byteOffset > have - bv.byteLength)
		return fail(L, AJAR_ERROR_BAD_INPUT, "bufferViews[%d]: needs %zu bytes at offset %zu but buffers[%d] has %zu",
			    v, bv.byteLength, bv.byteOffset, bv.buffer, have);
	if (offset > bv.byteLength || need > bv.byteLength - offset)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: needs %zu bytes at offset %zu but bufferViews[%d] has %zu", what,
			    need, offset, v, bv.byteLength);
	*p = m.buffers[(size_t)bv.buffer].data.data() + bv.byteOffset + offset;
	return AJAR_OK;
}

/* Reads accessors[idx] (`attr` of `ctx`, for messages), which must have
 * `ncomp` components, into p. */
ajar_status accessor_read(const Loader &L, const std::string &ctx, const char *attr, int idx, int ncomp, Packed &p)
{
	const tg::Model &m = L.model;
	if (idx < 0 || (size_t)idx >= m.accessors.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s: accessors[%d] does not exist (%zu accessors)", ctx.c_str(),
			    attr, idx, m.accessors.size());
	char what[512];
	snprintf(what, sizeof what, "%s: accessors[%d] (%s)", ctx.c_str(), idx, attr);
	const tg::Accessor &a = m.accessors[(size_t)idx];
	int csize = gltf_component_size(a.componentType), nc = type_components(a.type);
	if (!csize)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: unsupported componentType %d", what, a.componentType);
	if (nc != ncomp)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: has type %d, expected %d components", what, a.type, ncomp);
	if (a.count > (size_t)INT32_MAX)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: count %zu is too large", what, a.count);
	size_t elem = (size_t)csize * (size_t)nc;
	p.count = a.count;
	p.ctype = a.componentType;
	p.ncomp = nc;
	p.normalized = a.normalized;

	if (a.bufferView >= 0) {
		if ((size_t)a.bufferView >= m.bufferViews.size())
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: bufferViews[%d] does not exist (%zu buffer views)", what,
				    a.bufferView, m.bufferViews.size());
		size_t stride = m.bufferViews[(size_t)a.bufferView].byteStride;
		if (stride == 0)
			stride = elem;
		/* glTF caps byteStride at 252; the cap also keeps the sizes below
		 * far from overflow. */
		if (stride < elem || stride > 252)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: byteStride %zu of bufferViews[%d] does not fit %zu-byte elements",
				    what, stride, a.bufferView, elem);
		size_t need = a.count ? stride * (a.count - 1) + elem : 0;
		const uint8_t *src = nullptr;
		ajar_status st = view_range(L, what, a.bufferView, a.byteOffset, need, &src);
		if (st)
			return st;
		p.bytes.resize(a.count * elem);
		for (size_t i = 0; i < a.count; i++)
			memcpy(&p.bytes[i * elem], src + i * stride, elem);
	} else {
		/* No buffer view: all zeros, unless sparse values replace some. No
		 * data bounds the count here, so a sanity limit does. */
		if (a.count > ((size_t)1 << 24))
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: %zu elements without a bufferView", what, a.count);
		p.bytes.assign(a.count * elem, 0);
	}

	if (a.sparse.isSparse) {
		const auto &sp = a.sparse;
		int isize = gltf_component_size(sp.indices.componentType);
		if (sp.count < 0 || (size_t)sp.count > a.count || sp.indices.byteOffset < 0 || sp.values.byteOffset < 0 ||
		    isize == 0 || sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
		    sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
		    sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: invalid sparse (count %d, index type %d)", what, sp.count,
				    sp.indices.componentType);
		size_t n = (size_t)sp.count;
		char swhat[600];
		const uint8_t *isrc = nullptr, *vsrc = nullptr;
		snprintf(swhat, sizeof swhat, "%s: sparse.indices", what);
		ajar_status st = view_range(L, swhat, sp.indices.bufferView, (size_t)sp.indices.byteOffset,
					    n * (size_t)isize, &isrc);
		if (st)
			return st;
		snprintf(swhat, sizeof swhat, "%s: sparse.values", what);
		st = view_range(L, swhat, sp.values.bufferView, (size_t)sp.values.byteOffset, n * elem, &vsrc);
		if (st)
			return st;
		for (size_t k = 0; k < n; k++) {
			uint32_t i = 0;
			if (isize == 1) {
				i = isrc[k];
			} else if (isize == 2) {
				uint16_t v;
				memcpy(&v, isrc + 2 * k, 2);
				i = v;
			} else {
				memcpy(&i, isrc + 4 * k, 4);
			}
			if (i >= a.count)
				return fail(L, AJAR_ERROR_BAD_INPUT, "%s: sparse index %u out of range (%zu elements)", what, i,
					    a.count);
			memcpy(&p.bytes[i * elem], vsrc + k * elem, elem);
		}
	}
	return AJAR_OK;
}

std::vector<float> to_floats(const Packed &p)
{
	std::vector<float> out(p.count * (size_t)p.ncomp);
	gltf_to_floats(p.bytes.data(), out.size(), p.ctype, p.normalized, out.data());
	return out;
}

ajar_status to_indices(const Loader &L, const std::string &ctx, int acc, const Packed &p, std::vector<uint32_t> &out)
{
	if (p.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && p.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
	    p.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: accessors[%d] (indices): componentType %d is not an unsigned integer",
			    ctx.c_str(), acc, p.ctype);
	out.resize(p.count);
	gltf_to_indices(p.bytes.data(), p.count, gltf_component_size(p.ctype), out.data());
	return AJAR_OK;
}

/* ---- Transforms (column-major 4x4, element (r, c) at [4c + r]) --------- */

/* T * R * S (translation, rotation quaternion x y z w, scale) as a
 * matrix; `what` names the node for the message of a zero quaternion. */
ajar_status trs_matrix(const Loader &L, const char *what, const double t[3], const double q[4], const double s[3],
		       double m[16])
{
	if (!gltf_trs_matrix(t, q, s, m))
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: rotation is a zero quaternion", what);
	return AJAR_OK;
}

/* The node's local matrix: `matrix`, or T * R * S. */
ajar_status node_local(const Loader &L, int i, double m[16])
{
	const tg::Node &n = L.model.nodes[(size_t)i];
	if (!n.matrix.empty()) {
		if (n.matrix.size() != 16)
			return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: matrix has %zu numbers, expected 16", i,
				    n.matrix.size());
		for (int k = 0; k < 16; k++)
			m[k] = n.matrix[(size_t)k];
		return AJAR_OK;
	}
	if ((!n.translation.empty() && n.translation.size() != 3) || (!n.rotation.empty() && n.rotation.size() != 4) ||
	    (!n.scale.empty() && n.scale.size() != 3))
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: translation, rotation or scale has the wrong length", i);
	double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
	for (int k = 0; k < 3 && !n.translation.empty(); k++)
		t[k] = n.translation[(size_t)k];
	for (int k = 0; k < 4 && !n.rotation.empty(); k++)
		q[k] = n.rotation[(size_t)k];
	for (int k = 0; k < 3 && !n.scale.empty(); k++)
		s[k] = n.scale[(size_t)k];
	char ctx[32];
	snprintf(ctx, sizeof ctx, "nodes[%d]", i);
	return trs_matrix(L, ctx, t, q, s, m);
}

/* ---- Extras and extensions ----------------------------------------------- */

const tg::Value *value_member(const tg::Value &v, const char *key)
{
	if (!v.IsObject() || !v.Has(key))
		return nullptr;
	return &v.Get(key);
}

/* Portal markers: true, or a non-zero number (Blender custom properties). */
bool value_truthy(const tg::Value *v)
{
	if (!v)
		return false;
	if (v->IsBool())
		return v->Get<bool>();
	if (v->IsNumber())
		return v->GetNumberAsDouble() != 0.0;
	return false;
}

/* extensions[ext][key] as a number in [lo, hi], or `def` if absent. */
ajar_status ext_number(const Loader &L, int mi, const tg::ExtensionMap &exts, const char *ext, const char *key,
		       double def, double lo, double hi, double *out)
{
	*out = def;
	auto it = exts.find(ext);
	if (it == exts.end())
		return AJAR_OK;
	const tg::Value *v = value_member(it->second, key);
	if (!v)
		return AJAR_OK;
	if (!v->IsNumber() || !(v->GetNumberAsDouble() >= lo && v->GetNumberAsDouble() <= hi))
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s must be a number in [%g, %g]", mi, ext, key, lo,
			    hi);
	*out = v->GetNumberAsDouble();
	return AJAR_OK;
}

/* A member of extensions[ext] that Ajar does not read (a texture, a tint):
 * one warning naming it and what is used instead. */
void ext_unread(const Loader &L, int mi, const tg::ExtensionMap &exts, const char *ext, const char *key,
		const char *instead)
{
	auto it = exts.find(ext);
	if (it != exts.end() && value_member(it->second, key))
		log_msg(AJAR_LOG_WARNING, "%s: materials[%d]: %s.%s is not supported; %s", L.file, mi, ext, key, instead);
}

/* extensions[ext][key] as a colour: 3 finite numbers in [0, hi], or `def`
 * if absent. */
ajar_status ext_color(const Loader &L, int mi, const tg::ExtensionMap &exts, const char *ext, const char *key,
		      const V3 &def, double hi, V3 *out)
{
	*out = def;
	auto it = exts.find(ext);
	const tg::Value *c = it == exts.end() ? nullptr : value_member(it->second, key);
	if (!c)
		return AJAR_OK;
	double v[3];
	bool ok = c->IsArray() && c->ArrayLen() == 3;
	for (int k = 0; ok && k < 3; k++) {
		ok = c->Get(k).IsNumber();
		v[k] = ok ? c->Get(k).GetNumberAsDouble() : 0.0;
		ok = ok && v[k] >= 0.0 && v[k] <= hi;
	}
	if (!ok)
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s must be 3 numbers in [0, %g]", mi, ext, key, hi);
	*out = v3((float)v[0], (float)v[1], (float)v[2]);
	return AJAR_OK;
}

/* "resolution": [w, h] in an extras object, if there. */
ajar_status read_resolution(Loader &L, const tg::Value &extras, const char *where)
{
	const tg::Value *r = value_member(extras, "resolution");
	if (!r || L.s->width)
		return AJAR_OK;
	if (!r->IsArray() || r->ArrayLen() != 2 || !r->Get(0).IsNumber() || !r->Get(1).IsNumber() ||
	    !(r->Get(0).GetNumberAsDouble() >= 1 && r->Get(0).GetNumberAsDouble() <= AJAR_MAX_SIDE) ||
	    !(r->Get(1).GetNumberAsDouble() >= 1 && r->Get(1).GetNumberAsDouble() <= AJAR_MAX_SIDE))
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.resolution must be [width, height] in 1..%u", where,
			    AJAR_MAX_SIDE);
	L.s->width = (uint32_t)r->Get(0).GetNumberAsDouble();
	L.s->height = (uint32_t)r->Get(1).GetNumberAsDouble();
	return AJAR_OK;
}

ajar_status read_environment(Loader &L, const tg::Value &extras, const char *where)
{
	const tg::Value *env = value_member(extras, "environment");
	if (!env)
		return AJAR_OK;
	if (!env->IsObject())
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment is not an object", where);
	double strength = 1.0;
	if (const tg::Value *v = value_member(*env, "strength")) {
		if (!v->IsNumber() || !(v->GetNumberAsDouble() >= 0.0) || !std::isfinite(v->GetNumberAsDouble()))
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.strength must be a number >= 0", where);
		strength = v->GetNumberAsDouble();
	}
	if (const tg::Value *v = value_member(*env, "rotation")) {
		if (!v->IsNumber() || !std::isfinite(v->GetNumberAsDouble()))
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.rotation must be a number (degrees)",
				    where);
		ajar_status st = scene_set_env_rotation(L.s, v->GetNumberAsDouble());
		if (st)
			return st;
	}
	if (const tg::Value *img = value_member(*env, "image")) {
		if (!img->IsString() || img->Get<std::string>().empty())
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.image is not a file name", where);
		std::string name = img->Get<std::string>();
		std::string path = name[0] == '/' ? name : L.dir + "/" + name;
		if (access(path.c_str(), F_OK) == 0 && !confined(L, path, name))
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.image: %s", where, L.refused.c_str());
		ajar_status st = scene_load_env_image(L.s, path.c_str(), (float)strength);
		if (st) {
			std::string msg = ajar_last_error();
			return fail(L, st, "%s.extras.environment.image: %s", where, msg.c_str());
		}
		return AJAR_OK;
	}
	const tg::Value *col = value_member(*env, "color");
	float rgb[3];
	if (!col || !col->IsArray() || col->ArrayLen() != 3)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment needs \"color\": [r, g, b] or \"image\"", where);
	for (int c = 0; c < 3; c++) {
		const tg::Value &v = col->Get(c);
		if (!v.IsNumber() || !(v.GetNumberAsDouble() >= 0.0) || !std::isfinite(v.GetNumberAsDouble()))
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s.extras.environment.color must be 3 numbers >= 0", where);
		rgb[c] = (float)(v.GetNumberAsDouble() * strength);
	}
	scene_set_env_color(L.s, v3(rgb[0], rgb[1], rgb[2]));
	return AJAR_OK;
}

/* ---- Materials and textures ---------------------------------------------- */

/* images[i] as a scene texture (RGBA8), converted once. */
ajar_status image_texture(Loader &L, int i, int *id)
{
	if (L.image_textures[(size_t)i] >= 0) {
		*id = L.image_textures[(size_t)i];
		return AJAR_OK;
	}
	const tg::Image &im = L.model.images[(size_t)i];
	int bytes = im.bits == 16 ? 2 : im.bits == 8 ? 1 : 0;
	if (im.width <= 0 || im.height <= 0 || im.component < 1 || im.component > 4 || !bytes)
		return fail(L, AJAR_ERROR_BAD_INPUT, "images[%d]: not decoded (%dx%d, %d channels of %d bits)", i, im.width,
			    im.height, im.component, im.bits);
	size_t n = (size_t)im.width * (size_t)im.height, comp = (size_t)im.component;
	if (im.image.size() < n * comp * (size_t)bytes)
		return fail(L, AJAR_ERROR_BAD_INPUT, "images[%d]: %zu bytes of pixels, expected %zu", i, im.image.size(),
			    n * comp * (size_t)bytes);
	std::vector<uint8_t> rgba(n * 4);
	gltf_rgba8(im.image.data(), n, comp, bytes, rgba.data());
	uint32_t tid;
	ajar_status st = scene_add_texture(L.s, (uint32_t)im.width, (uint32_t)im.height, rgba.data(), &tid);
	if (st)
		return st;
	L.image_textures[(size_t)i] = (int)tid;
	*id = (int)tid;
	return AJAR_OK;
}

/* A number, or a JSON array of n numbers, of a KHR_texture_transform. */
bool transform_numbers(const tg::Value &ext, const char *key, int n, double *out)
{
	const tg::Value *v = value_member(ext, key);
	if (!v)
		return true;
	if (n == 1) {
		if (!v->IsNumber() || !std::isfinite(v->GetNumberAsDouble()))
			return false;
		out[0] = v->GetNumberAsDouble();
		return true;
	}
	if (!v->IsArray() || v->ArrayLen() != (size_t)n)
		return false;
	for (int i = 0; i < n; i++) {
		if (!v->Get(i).IsNumber() || !std::isfinite(v->Get(i).GetNumberAsDouble()))
			return false;
		out[i] = v->Get(i).GetNumberAsDouble();
	}
	return true;
}

int wrap_mode(int gl)
{
	return gl == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TEX_WRAP_CLAMP
	       : gl == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TEX_WRAP_MIRROR
							     : TEX_WRAP_REPEAT;
}

/* materials[mi]'s texture `slot` (textures[index], coordinate set
 * texcoord, the textureInfo's extensions) as a scene texture: the image's
 * texels, the sampler's wrap modes and magnification filter (there are no
 * mipmaps: pixel sampling filters), the coordinate set and
 * KHR_texture_transform (T R S, its texCoord replacing the set). *id is -1
 * where there is no texture. */
ajar_status texture_use(Loader &L, int mi, const char *slot, int index, int texcoord, const tg::ExtensionMap &exts,
			int *id)
{
	*id = -1;
	if (index < 0)
		return AJAR_OK;
	const tg::Model &m = L.model;
	if ((size_t)index >= m.textures.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d].%s: textures[%d] does not exist (%zu textures)", mi, slot,
			    index, m.textures.size());
	const tg::Texture &tex = m.textures[(size_t)index];
	if (tex.source < 0 || (size_t)tex.source >= m.images.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "textures[%d]: images[%d] does not exist (%zu images)", index,
			    tex.source, m.images.size());
	int flags = 0;
	if (tex.sampler >= 0) {
		if ((size_t)tex.sampler >= m.samplers.size())
			return fail(L, AJAR_ERROR_BAD_INPUT, "textures[%d]: samplers[%d] does not exist (%zu samplers)", index,
				    tex.sampler, m.samplers.size());
		const tg::Sampler &sm = m.samplers[(size_t)tex.sampler];
		flags |= wrap_mode(sm.wrapS) | wrap_mode(sm.wrapT) << 2;
		if (sm.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST)
			flags |= TEX_NEAREST;
	}
	float xf[6] = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
	auto it = exts.find("KHR_texture_transform");
	if (it != exts.end()) {
		double off[2] = {0.0, 0.0}, rot = 0.0, sc[2] = {1.0, 1.0}, tc = texcoord;
		if (!transform_numbers(it->second, "offset", 2, off) || !transform_numbers(it->second, "rotation", 1, &rot) ||
		    !transform_numbers(it->second, "scale", 2, sc) || !transform_numbers(it->second, "texCoord", 1, &tc) ||
		    !(tc >= 0.0 && tc == std::floor(tc)))
			return fail(L, AJAR_ERROR_BAD_INPUT,
				    "materials[%d].%s.extensions.KHR_texture_transform: offset and scale must be 2 numbers, "
				    "rotation a number, texCoord an integer >= 0",
				    mi, slot);
		/* uv' = T(offset) R(rotation) S(scale) uv with R = [cos sin;
		 * -sin cos] in (u, v): counter-clockwise as the image is seen
		 * (v grows downwards), which TextureTransformTest's markers
		 * confirm (the other sign hits its red "opposite" marker). */
		double c = std::cos(rot), sn = std::sin(rot);
		xf[0] = (float)(c * sc[0]);
		xf[1] = (float)(sn * sc[1]);
		xf[2] = (float)off[0];
		xf[3] = (float)(-sn * sc[0]);
		xf[4] = (float)(c * sc[1]);
		xf[5] = (float)off[1];
		texcoord = (int)std::fmin(tc, 1e6);
	}
	if (texcoord > 1) {
		log_msg(AJAR_LOG_WARNING, "%s: materials[%d].%s uses TEXCOORD_%d; only TEXCOORD_0 and _1 are supported, texture ignored",
			L.file, mi, slot, texcoord);
		return AJAR_OK;
	}
	if (texcoord == 1)
		flags |= TEX_UV1;
	int img = -1;
	ajar_status st = image_texture(L, tex.source, &img);
	uint32_t tid;
	if (!st)
		st = scene_add_texture_use(L.s, (uint32_t)img, flags, xf, &tid);
	if (!st)
		*id = (int)tid;
	return st;
}

/* A texture named inside a material extension (extensions[ext][key], a
 * textureInfo: index, texCoord and its own extensions), or *id = -1. */
ajar_status ext_texture(Loader &L, int mi, const tg::ExtensionMap &exts, const char *ext, const char *key, int *id)
{
	*id = -1;
	auto it = exts.find(ext);
	const tg::Value *info = it == exts.end() ? nullptr : value_member(it->second, key);
	if (!info)
		return AJAR_OK;
	const tg::Value *index = value_member(*info, "index"), *texcoord = value_member(*info, "texCoord");
	if (!index || !index->IsNumber() || (texcoord && !texcoord->IsNumber()))
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s needs a numeric index (and texCoord)", mi, ext,
			    key);
	tg::ExtensionMap own;
	const tg::Value *e = value_member(*info, "extensions");
	if (e && e->IsObject())
		for (const std::string &k : e->Keys())
			own[k] = e->Get(k);
	char slot[96];
	snprintf(slot, sizeof slot, "%s.%s", ext, key);
	return texture_use(L, mi, slot, (int)index->GetNumberAsDouble(), texcoord ? (int)texcoord->GetNumberAsDouble() : 0,
			   own, id);
}

/* KHR_materials_volume: a thickness above 0 makes the material a solid
 * that transmission refracts into (MATERIAL_VOLUME), absorbing by
 * sigma = -ln(attenuationColor) / attenuationDistance inside; without it
 * (or with thickness 0) transmission is thin-walled, as glTF defines. */
ajar_status load_volume(Loader &L, int mi, const tg::ExtensionMap &exts, ::Material *m)
{
	double thickness, distance;
	ajar_status st;
	if ((st = ext_number(L, mi, exts, "KHR_materials_volume", "thicknessFactor", 0.0, 0.0, 1e30, &thickness)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_volume", "attenuationDistance", INFINITY, 0.0, INFINITY,
			     &distance)))
		return st;
	if (!(thickness > 0.0))
		return AJAR_OK;
	ext_unread(L, mi, exts, "KHR_materials_volume", "thicknessTexture", "thicknessFactor alone is used");
	m->flags |= MATERIAL_VOLUME;
	auto it = exts.find("KHR_materials_volume");
	const tg::Value *c = value_member(it->second, "attenuationColor");
	double col[3] = {1.0, 1.0, 1.0};
	if (c) {
		if (!c->IsArray() || c->ArrayLen() != 3)
			return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: KHR_materials_volume.attenuationColor needs 3 numbers",
				    mi);
		for (int k = 0; k < 3; k++) {
			if (!c->Get(k).IsNumber() || !(c->Get(k).GetNumberAsDouble() >= 0.0 && c->Get(k).GetNumberAsDouble() <= 1.0))
				return fail(L, AJAR_ERROR_BAD_INPUT,
					    "materials[%d]: KHR_materials_volume.attenuationColor must be in [0, 1]", mi);
			col[k] = c->Get(k).GetNumberAsDouble();
		}
	}
	if (!(distance > 0.0))
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: KHR_materials_volume.attenuationDistance must be above 0",
			    mi);
	float sigma[3];
	for (int k = 0; k < 3; k++) /* a colour of 0 absorbs everything: a large finite coefficient */
		sigma[k] = std::isinf(distance) ? 0.0f : (float)fmin(-log(fmax(col[k], 1e-30)) / distance, 1e30);
	m->sigma = v3(sigma[0], sigma[1], sigma[2]);
	return AJAR_OK;
}

/* KHR_materials_specular (factor and colour with their textures), _sheen,
 * _clearcoat and _anisotropy (kernels/material/bsdf.h, "Layers"). */
ajar_status load_material_layers(Loader &L, int mi, const tg::ExtensionMap &exts, ::Material *m)
{
	ajar_status st;
	double sheen_r, cc, cc_r, aniso, rot;
	V3 tint, sheen;
	int spec_t, tint_t, sheen_t, sheen_rt, cc_t, cc_rt, cc_nt, aniso_t;
	if ((st = ext_color(L, mi, exts, "KHR_materials_specular", "specularColorFactor", v3(1.0f, 1.0f, 1.0f), 1e30,
			    &tint)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_specular", "specularTexture", &spec_t)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_specular", "specularColorTexture", &tint_t)) ||
	    (st = ext_color(L, mi, exts, "KHR_materials_sheen", "sheenColorFactor", v3(0.0f, 0.0f, 0.0f), 1.0, &sheen)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_sheen", "sheenRoughnessFactor", 0.0, 0.0, 1.0, &sheen_r)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_sheen", "sheenColorTexture", &sheen_t)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_sheen", "sheenRoughnessTexture", &sheen_rt)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_clearcoat", "clearcoatFactor", 0.0, 0.0, 1.0, &cc)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_clearcoat", "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, &cc_r)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatTexture", &cc_t)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatRoughnessTexture", &cc_rt)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatNormalTexture", &cc_nt)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_anisotropy", "anisotropyStrength", 0.0, 0.0, 1.0, &aniso)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_anisotropy", "anisotropyRotation", 0.0, -1e6, 1e6, &rot)) ||
	    (st = ext_texture(L, mi, exts, "KHR_materials_anisotropy", "anisotropyTexture", &aniso_t)))
		return st;
	m->specular_tex = spec_t + 1;
	m->specular_color = tint;
	m->specular_color_tex = tint_t + 1;
	if (tint_t >= 0 || tint.x != 1.0f || tint.y != 1.0f || tint.z != 1.0f)
		m->flags |= MATERIAL_TINTED;
	m->sheen_color = sheen;
	m->sheen_roughness = (float)sheen_r;
	m->sheen_color_tex = sheen_t + 1;
	m->sheen_rough_tex = sheen_rt + 1;
	m->clearcoat = (float)cc;
	m->clearcoat_roughness = (float)cc_r;
	m->clearcoat_tex = cc_t + 1;
	m->clearcoat_rough_tex = cc_rt + 1;
	m->clearcoat_normal_tex = cc_nt + 1;
	m->clearcoat_normal_scale = 1.0f;
	auto it = exts.find("KHR_materials_clearcoat");
	const tg::Value *info = it == exts.end() ? nullptr : value_member(it->second, "clearcoatNormalTexture");
	const tg::Value *scale = info ? value_member(*info, "scale") : nullptr;
	if (scale) {
		if (!scale->IsNumber() || !std::isfinite(scale->GetNumberAsDouble()))
			return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: clearcoatNormalTexture.scale is not a finite number",
				    mi);
		m->clearcoat_normal_scale = (float)scale->GetNumberAsDouble();
	}
	m->anisotropy = (float)aniso;
	m->anisotropy_rotation = (float)std::remainder(rot, 2.0 * M_PI); /* [-pi, pi] */
	m->anisotropy_tex = aniso_t + 1;
	if (aniso_t >= 0 && !(aniso > 0.0))
		m->anisotropy_tex = 0; /* the texture's B multiplies a strength of 0 */
	for (const auto &e : exts) {
		if (!gltf_material_extension_read(e.first.data(), e.first.size()))
			log_msg(AJAR_LOG_WARNING, "%s: materials[%d] (%s): %s is not supported; ignored", L.file, mi,
				L.model.materials[(size_t)mi].name.c_str(), e.first.c_str());
	}
	return AJAR_OK;
}

ajar_status in_unit(const Loader &L, int mi, const char *name, double v)
{
	if (!(v >= 0.0 && v <= 1.0))
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s %g is not in [0, 1]", mi, name, v);
	return AJAR_OK;
}

ajar_status load_material(Loader &L, int mi, uint32_t *id)
{
	const tg::Material &gm = L.model.materials[(size_t)mi];
	const tg::PbrMetallicRoughness &pbr = gm.pbrMetallicRoughness;
	::Material m;
	memset(&m, 0, sizeof m);
	ajar_status st = AJAR_OK;
	if (pbr.baseColorFactor.size() != 4)
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: baseColorFactor has %zu numbers, expected 4", mi,
			    pbr.baseColorFactor.size());
	for (int c = 0; c < 4 && !st; c++)
		st = in_unit(L, mi, "baseColorFactor", pbr.baseColorFactor[(size_t)c]);
	if (!st)
		st = in_unit(L, mi, "metallicFactor", pbr.metallicFactor);
	if (!st)
		st = in_unit(L, mi, "roughnessFactor", pbr.roughnessFactor);
	if (st)
		return st;
	m.base_color = v3((float)pbr.baseColorFactor[0], (float)pbr.baseColorFactor[1], (float)pbr.baseColorFactor[2]);
	m.metallic = (float)pbr.metallicFactor;
	m.roughness = (float)pbr.roughnessFactor;
	m.base_tex = -1;

	double strength, transmission, ior, specular;
	if ((st = ext_number(L, mi, gm.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0, 0.0,
			     1e30, &strength)) ||
	    (st = ext_number(L, mi, gm.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0, 0.0, 1.0,
			     &transmission)) ||
	    (st = ext_number(L, mi, gm.extensions, "KHR_materials_ior", "ior", 1.5, 1.0, 10.0, &ior)) ||
	    (st = ext_number(L, mi, gm.extensions, "KHR_materials_specular", "specularFactor", 1.0, 0.0, 1.0,
			     &specular)))
		return st;
	if (!gm.emissiveFactor.empty()) {
		if (gm.emissiveFactor.size() != 3)
			return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: emissiveFactor has %zu numbers, expected 3", mi,
				    gm.emissiveFactor.size());
		for (int c = 0; c < 3 && !st; c++)
			st = in_unit(L, mi, "emissiveFactor", gm.emissiveFactor[(size_t)c]);
		if (st)
			return st;
		m.emission = v3((float)(gm.emissiveFactor[0] * strength), (float)(gm.emissiveFactor[1] * strength),
				(float)(gm.emissiveFactor[2] * strength));
	}
	m.transmission = (float)transmission;
	m.ior = (float)ior;
	m.specular = (float)specular;
	m.flags = gm.doubleSided ? MATERIAL_DOUBLE_SIDED : 0;
	m.alpha_cutoff = (float)gm.alphaCutoff;
	m.base_alpha = (float)pbr.baseColorFactor[3];
	if (gm.alphaMode == "MASK")
		m.flags |= MATERIAL_ALPHA_MASK;
	else if (gm.alphaMode == "BLEND")
		m.flags |= MATERIAL_ALPHA_BLEND;
	else if (gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty())
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: alphaMode \"%s\" is not OPAQUE, MASK or BLEND", mi,
			    gm.alphaMode.c_str());

	int base = -1, mr = -1, em = -1;
	const tg::TextureInfo &bt = pbr.baseColorTexture, &mt = pbr.metallicRoughnessTexture, &et = gm.emissiveTexture;
	if ((st = texture_use(L, mi, "baseColorTexture", bt.index, bt.texCoord, bt.extensions, &base)) ||
	    (st = texture_use(L, mi, "metallicRoughnessTexture", mt.index, mt.texCoord, mt.extensions, &mr)) ||
	    (st = texture_use(L, mi, "emissiveTexture", et.index, et.texCoord, et.extensions, &em)))
		return st;
	m.base_tex = base;
	m.mr_tex = mr + 1;
	m.emissive_tex = em + 1;
	const tg::NormalTextureInfo &nt = gm.normalTexture;
	int nrm = -1;
	if ((st = texture_use(L, mi, "normalTexture", nt.index, nt.texCoord, nt.extensions, &nrm)))
		return st;
	if (!std::isfinite(nt.scale))
		return fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: normalTexture.scale is not finite", mi);
	m.normal_tex = nrm + 1;
	m.normal_scale = (float)nt.scale;
	int tr = -1;
	if ((st = ext_texture(L, mi, gm.extensions, "KHR_materials_transmission", "transmissionTexture", &tr)) ||
	    (st = load_volume(L, mi, gm.extensions, &m)))
		return st;
	m.transmission_tex = tr + 1;
	if ((st = load_material_layers(L, mi, gm.extensions, &m)))
		return st;
	return scene_add_material(L.s, &m, id);
}

/* The glTF default material (spec 3.9.6): white, metallic 1, roughness 1. */
ajar_status default_material(Loader &L, uint32_t *id)
{
	if (L.default_material < 0) {
		::Material m;
		memset(&m, 0, sizeof m);
		m.base_color = v3(1.0f, 1.0f, 1.0f);
		m.base_tex = -1;
		m.metallic = 1.0f;
		m.roughness = 1.0f;
		m.ior = 1.5f;
		m.specular = 1.0f;
		m.alpha_cutoff = 0.5f;
		uint32_t mid;
		ajar_status st = scene_add_material(L.s, &m, &mid);
		if (st)
			return st;
		L.default_material = (int)mid;
	}
	*id = (uint32_t)L.default_material;
	return AJAR_OK;
}

/* ---- Meshes and nodes ---------------------------------------------------- */

/* Triangles of a portal node, gathered over its primitives so the node is
 * one portal. */
struct PortalMesh {
	std::vector<float> pos;
	std::vector<uint32_t> idx;
};

/* The primitive's index list as triangles (strips and fans unrolled,
 * their degenerate stitching triangles dropped). */
ajar_status triangle_list(const Loader &L, const std::string &what, int mode, const std::vector<uint32_t> &in,
			  std::vector<uint32_t> &out)
{
	size_t n = in.size();
	if (mode == TINYGLTF_MODE_TRIANGLES) {
		if (n % 3)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: %zu vertices do not make whole triangles", what.c_str(), n);
		out = in;
		return AJAR_OK;
	}
	out.assign(n > 2 ? 3 * (n - 2) : 0, 0);
	out.resize(gltf_unroll(mode == TINYGLTF_MODE_TRIANGLE_STRIP, in.data(), n, out.data()));
	return AJAR_OK;
}

/* Tangents for a normal map where the mesh has none (tangents.c); the
 * vertices it splits in two are appended to pos, nrm, uv and the other
 * per-vertex arrays in `more` (each `width` floats a vertex). */
struct VertexArray {
	std::vector<float> *v;
	size_t width;
};

ajar_status generate_tangents(const Loader &L, std::vector<float> &pos, std::vector<float> &nrm,
			      std::vector<float> &uvs, std::vector<VertexArray> more, std::vector<uint32_t> &tri,
			      std::vector<float> &tan)
{
	size_t nv = pos.size() / 3, total = 0;
	std::vector<uint32_t> twin(nv);
	float *t = nullptr;
	if (tangents_generate(pos.data(), nrm.empty() ? nullptr : nrm.data(), uvs.data(), nv, tri.data(), tri.size() / 3,
			      twin.data(), &t, &total) != AJAR_OK)
		return fail(L, AJAR_ERROR_OUT_OF_MEMORY, "out of memory for tangents");
	tan.assign(t, t + 4 * total);
	free(t);
	more.push_back({&pos, 3});
	if (!nrm.empty())
		more.push_back({&nrm, 3});
	more.push_back({&uvs, 2});
	for (const VertexArray &a : more) {
		a.v->resize(total * a.width);
		for (size_t v = 0; v < nv; v++)
			if (twin[v] != UINT32_MAX)
				for (size_t c = 0; c < a.width; c++)
					(*a.v)[twin[v] * a.width + c] = (*a.v)[v * a.width + c];
	}
	return AJAR_OK;
}

ajar_status load_primitive(Loader &L, int mi, int pi, const double world[16], const double nm[3][3], bool flip,
			   PortalMesh *portal)
{
	const tg::Primitive &pr = L.model.meshes[(size_t)mi].primitives[(size_t)pi];
	char wbuf[64];
	snprintf(wbuf, sizeof wbuf, "meshes[%d].primitives[%d]", mi, pi);
	const std::string what = wbuf;
	int mode = pr.mode < 0 ? TINYGLTF_MODE_TRIANGLES : pr.mode;
	if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
	    mode != TINYGLTF_MODE_TRIANGLE_FAN) {
		log_msg(AJAR_LOG_WARNING, "%s: %s: mode %d (points or lines) skipped", L.file, what.c_str(), mode);
		return AJAR_OK;
	}
	auto pit = pr.attributes.find("POSITION");
	if (pit == pr.attributes.end()) {
		log_msg(AJAR_LOG_WARNING, "%s: %s: no POSITION, skipped", L.file, what.c_str());
		return AJAR_OK;
	}
	Packed pp;
	ajar_status st = accessor_read(L, what, "POSITION", pit->second, 3, pp);
	if (st)
		return st;
	size_t nv = pp.count;
	std::vector<float> pos = to_floats(pp);

	std::vector<uint32_t> idx, tri;
	if (pr.indices >= 0) {
		Packed pi_;
		if ((st = accessor_read(L, what, "indices", pr.indices, 1, pi_)) ||
		    (st = to_indices(L, what, pr.indices, pi_, idx)))
			return st;
	} else {
		idx.resize(nv);
		for (size_t i = 0; i < nv; i++)
			idx[i] = (uint32_t)i;
	}
	for (size_t i = 0; i < idx.size(); i++)
		if (idx[i] >= nv)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: index %u (at %zu) out of range (%zu vertices)", what.c_str(),
				    idx[i], i, nv);
	if ((st = triangle_list(L, what, mode, idx, tri)))
		return st;
	for (size_t v = 0; v < nv; v++)
		for (int c = 0; c < 3; c++)
			if (!std::isfinite(pos[3 * v + (size_t)c]))
				return fail(L, AJAR_ERROR_BAD_INPUT, "%s: vertex %zu: position is not finite", what.c_str(), v);
	if (flip)
		for (size_t t = 0; t < tri.size(); t += 3)
			std::swap(tri[t + 1], tri[t + 2]);
	gltf_transform_points(world, pos.data(), nv);
	uint32_t ntris = (uint32_t)(tri.size() / 3);

	if (portal) {
		uint32_t base = (uint32_t)(portal->pos.size() / 3);
		portal->pos.insert(portal->pos.end(), pos.begin(), pos.end());
		for (uint32_t k : tri)
			portal->idx.push_back(base + k);
		return AJAR_OK;
	}

	std::vector<float> nrm, uv;
	auto nit = pr.attributes.find("NORMAL");
	if (nit != pr.attributes.end()) {
		Packed pn;
		if ((st = accessor_read(L, what, "NORMAL", nit->second, 3, pn)))
			return st;
		if (pn.count != nv)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: NORMAL has %zu elements, POSITION %zu", what.c_str(),
				    pn.count, nv);
		nrm = to_floats(pn);
		gltf_transform_normals(nm, nrm.data(), nv);
	}
	std::vector<float> uv1, col;
	const char *sets[2] = {"TEXCOORD_0", "TEXCOORD_1"};
	for (int k = 0; k < 2; k++) {
		auto uit = pr.attributes.find(sets[k]);
		if (uit == pr.attributes.end())
			continue;
		Packed pu;
		if ((st = accessor_read(L, what, sets[k], uit->second, 2, pu)))
			return st;
		if (pu.count != nv)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s has %zu elements, POSITION %zu", what.c_str(), sets[k],
				    pu.count, nv);
		(k ? uv1 : uv) = to_floats(pu);
	}
	/* COLOR_0: RGB or RGBA, float or normalized unsigned integers, linear. */
	auto cit = pr.attributes.find("COLOR_0");
	if (cit != pr.attributes.end()) {
		int acc = cit->second;
		int nc = acc >= 0 && (size_t)acc < L.model.accessors.size()
				 ? type_components(L.model.accessors[(size_t)acc].type)
				 : 4;
		Packed pc;
		if ((st = accessor_read(L, what, "COLOR_0", acc, nc == 3 ? 3 : 4, pc)))
			return st;
		if (pc.count != nv)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: COLOR_0 has %zu elements, POSITION %zu", what.c_str(),
				    pc.count, nv);
		if (pc.ctype != TINYGLTF_COMPONENT_TYPE_FLOAT && !pc.normalized)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: accessors[%d] (COLOR_0): integer components must be normalized",
				    what.c_str(), acc);
		std::vector<float> c = to_floats(pc);
		col.assign(4 * nv, 1.0f);
		for (size_t v = 0; v < nv; v++)
			for (int j = 0; j < pc.ncomp; j++)
				col[4 * v + (size_t)j] = std::fmin(std::fmax(c[(size_t)pc.ncomp * v + (size_t)j], 0.0f), 1.0f);
	}
	uint32_t mat = 0;
	if (pr.material < 0) {
		st = default_material(L, &mat);
	} else if ((size_t)pr.material >= L.material_ids.size()) {
		st = fail(L, AJAR_ERROR_BAD_INPUT, "%s: materials[%d] does not exist (%zu materials)", what.c_str(),
			  pr.material, L.material_ids.size());
	} else {
		mat = L.material_ids[(size_t)pr.material];
	}
	if (st)
		return st;
	/* Tangents for a normal map: TANGENT (xyz by the node's matrix, w
	 * turned over where it mirrors), else generated from the normal
	 * map's coordinate set. */
	std::vector<float> tan;
	const ::Material &sm = L.s->materials[mat];
	if (sm.normal_tex || sm.clearcoat_normal_tex || sm.anisotropy > 0.0f) {
		/* the set of the normal map, the clear coat's, or TEXCOORD_0 */
		int tex = sm.normal_tex ? sm.normal_tex : sm.clearcoat_normal_tex;
		auto tit = pr.attributes.find("TANGENT");
		std::vector<float> &set = tex && (L.s->textures[tex - 1].flags & TEX_UV1) ? uv1 : uv;
		if (tit != pr.attributes.end()) {
			Packed pt;
			if ((st = accessor_read(L, what, "TANGENT", tit->second, 4, pt)))
				return st;
			if (pt.count != nv)
				return fail(L, AJAR_ERROR_BAD_INPUT, "%s: TANGENT has %zu elements, POSITION %zu", what.c_str(),
					    pt.count, nv);
			tan = to_floats(pt);
			gltf_transform_tangents(world, tan.data(), nv, flip);
		} else if (!set.empty()) {
			std::vector<VertexArray> more;
			std::vector<float> *other = &set == &uv ? &uv1 : &uv;
			if (!other->empty())
				more.push_back({other, 2});
			if (!col.empty())
				more.push_back({&col, 4});
			if ((st = generate_tangents(L, pos, nrm, set, more, tri, tan)) != AJAR_OK)
				return st;
			nv = pos.size() / 3;
		}
	}
	return scene_add_triangles_ex(L.s, what.c_str(), pos.data(), nrm.empty() ? nullptr : nrm.data(),
				      uv.empty() ? nullptr : uv.data(), uv1.empty() ? nullptr : uv1.data(),
				      col.empty() ? nullptr : col.data(), tan.empty() ? nullptr : tan.data(), (uint32_t)nv,
				      tri.data(), ntris, mat);
}

/* ---- Instances ------------------------------------------------------------ */

/* Triangles the mesh's primitives make (strips and fans counted as drawn,
 * points and lines none), from their accessors' counts. */
uint64_t mesh_triangles(const Loader &L, int mi)
{
	uint64_t n = 0;
	for (const tg::Primitive &pr : L.model.meshes[(size_t)mi].primitives) {
		int mode = pr.mode < 0 ? TINYGLTF_MODE_TRIANGLES : pr.mode;
		int acc = pr.indices;
		if (acc < 0) {
			auto it = pr.attributes.find("POSITION");
			acc = it == pr.attributes.end() ? -1 : it->second;
		}
		if (acc < 0 || (size_t)acc >= L.model.accessors.size())
			continue;
		n += gltf_mode_triangles(mode, L.model.accessors[(size_t)acc].count);
	}
	return n;
}

/* The accessors of node ni's EXT_mesh_gpu_instancing (-1 where absent)
 * and their count; false without the extension. */
bool gpu_instancing(const Loader &L, int ni, int acc[3], size_t *count)
{
	const tg::Node &n = L.model.nodes[(size_t)ni];
	auto it = n.extensions.find("EXT_mesh_gpu_instancing");
	if (it == n.extensions.end())
		return false;
	const tg::Value *attrs = value_member(it->second, "attributes");
	static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
	*count = 0;
	for (int k = 0; k < 3; k++) {
		const tg::Value *v = attrs ? value_member(*attrs, names[k]) : nullptr;
		acc[k] = v && v->IsNumber() ? (int)v->GetNumberAsDouble() : -1;
		if (acc[k] >= 0 && (size_t)acc[k] < L.model.accessors.size())
			*count = L.model.accessors[(size_t)acc[k]].count;
	}
	return true;
}

/* The transforms of node ni's copies: its world matrix, or with
 * EXT_mesh_gpu_instancing world x T x R x S of each instance. */
ajar_status node_copies(Loader &L, int ni, const double world[16], std::vector<double> &out)
{
	out.clear();
	int acc[3];
	size_t count = 0;
	if (!gpu_instancing(L, ni, acc, &count)) {
		out.assign(world, world + 16);
		return AJAR_OK;
	}
	char ctx[64];
	snprintf(ctx, sizeof ctx, "nodes[%d]: EXT_mesh_gpu_instancing", ni);
	if (acc[0] < 0 && acc[1] < 0 && acc[2] < 0)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: no TRANSLATION, ROTATION or SCALE", ctx);
	static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
	std::vector<float> v[3];
	for (int k = 0; k < 3; k++) {
		if (acc[k] < 0)
			continue;
		Packed p;
		ajar_status st = accessor_read(L, ctx, names[k], acc[k], k == 1 ? 4 : 3, p);
		if (st)
			return st;
		if (p.count != count)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: %s has %zu elements, the others %zu", ctx, names[k], p.count,
				    count);
		v[k] = to_floats(p);
	}
	out.resize(16 * count);
	for (size_t i = 0; i < count; i++) {
		double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
		for (int c = 0; c < 3 && !v[0].empty(); c++)
			t[c] = v[0][3 * i + (size_t)c];
		for (int c = 0; c < 4 && !v[1].empty(); c++)
			q[c] = v[1][4 * i + (size_t)c];
		for (int c = 0; c < 3 && !v[2].empty(); c++)
			sc[c] = v[2][3 * i + (size_t)c];
		double local[16];
		ajar_status st = trs_matrix(L, ctx, t, q, sc, local);
		if (st)
			return st;
		gltf_mat_mul(world, local, &out[16 * i]);
	}
	return AJAR_OK;
}

/* Whether primitive pi of mesh mi emits: its triangles stay world-space
 * copies, each an emitter of the light tables, never an instance's. */
bool primitive_emits(const Loader &L, int mi, int pi)
{
	int m = L.model.meshes[(size_t)mi].primitives[(size_t)pi].material;
	if (m < 0 || (size_t)m >= L.material_ids.size())
		return false;
	return v3_lum(L.s->materials[L.material_ids[(size_t)m]].emission) > 0.0f;
}

/* Mesh mi's primitives that do not emit, once, in object space: the
 * scene mesh its instances draw (-2 if it makes no triangles). */
ajar_status load_instanced_mesh(Loader &L, int mi)
{
	double id[16], nm[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	gltf_mat_identity(id);
	uint32_t first = L.s->ntris;
	const tg::Mesh &mesh = L.model.meshes[(size_t)mi];
	for (size_t p = 0; p < mesh.primitives.size(); p++) {
		if (primitive_emits(L, mi, (int)p))
			continue;
		ajar_status st = load_primitive(L, mi, (int)p, id, nm, false, nullptr);
		if (st)
			return st;
	}
	L.mesh_id[(size_t)mi] = -2;
	if (L.s->ntris == first)
		return AJAR_OK;
	char what[32];
	snprintf(what, sizeof what, "meshes[%d]", mi);
	uint32_t id_out;
	ajar_status st = scene_add_mesh_range(L.s, what, first, &id_out);
	if (!st)
		L.mesh_id[(size_t)mi] = (int)id_out;
	return st;
}

/* One copy of node ni's mesh under `world`: an instance of its object-space
 * mesh (and world-space copies of its emitting primitives), or all of it
 * flattened; a portal node's triangles go to the portals. */
ajar_status load_mesh_copy(Loader &L, int ni, const double world[16], bool is_portal, PortalMesh *portal)
{
	const tg::Node &n = L.model.nodes[(size_t)ni];
	double nm[3][3];
	double det = gltf_normal_matrix(world, nm);
	if (!(std::fabs(det) > 0.0) || !std::isfinite(det)) {
		log_msg(AJAR_LOG_WARNING, "%s: nodes[%d]: transform is singular (zero scale), mesh skipped", L.file, ni);
		return AJAR_OK;
	}
	const tg::Mesh &mesh = L.model.meshes[(size_t)n.mesh];
	bool inst = !is_portal && L.mesh_inst[(size_t)n.mesh];
	ajar_status st;
	if (inst && L.mesh_id[(size_t)n.mesh] == -1 && (st = load_instanced_mesh(L, n.mesh)))
		return st;
	if (inst && L.mesh_id[(size_t)n.mesh] >= 0) {
		char what[48];
		snprintf(what, sizeof what, "nodes[%d]", ni);
		if ((st = scene_add_instance(L.s, what, (uint32_t)L.mesh_id[(size_t)n.mesh], world)))
			return st;
	}
	for (size_t p = 0; p < mesh.primitives.size(); p++) {
		if (inst && !primitive_emits(L, n.mesh, (int)p))
			continue;
		st = load_primitive(L, n.mesh, (int)p, world, nm, det < 0.0, is_portal ? portal : nullptr);
		if (st)
			return st;
	}
	return AJAR_OK;
}

ajar_status load_mesh_node(Loader &L, int ni, const double world[16])
{
	const tg::Node &n = L.model.nodes[(size_t)ni];
	if ((size_t)n.mesh >= L.model.meshes.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: meshes[%d] does not exist (%zu meshes)", ni, n.mesh,
			    L.model.meshes.size());
	bool is_portal = value_truthy(value_member(n.extras, "portal"));
	PortalMesh portal;
	std::vector<double> copies;
	ajar_status st = node_copies(L, ni, world, copies);
	if (st)
		return st;
	for (size_t c = 0; c < copies.size() / 16; c++)
		if ((st = load_mesh_copy(L, ni, &copies[16 * c], is_portal, &portal)))
			return st;
	if (!is_portal)
		return AJAR_OK;
	if (portal.idx.empty()) {
		log_msg(AJAR_LOG_WARNING, "%s: nodes[%d]: portal has no triangles, ignored", L.file, ni);
		return AJAR_OK;
	}
	char what[64];
	snprintf(what, sizeof what, "nodes[%d] (portal)", ni);
	return scene_add_portal(L.s, what, portal.pos.data(), (uint32_t)(portal.pos.size() / 3), portal.idx.data(),
				(uint32_t)(portal.idx.size() / 3));
}

/* How often each mesh is drawn (walking the nodes as walk_nodes does,
 * which reports what is malformed), and which ones are kept once. */
void count_mesh_uses(Loader &L, const std::vector<int> &roots)
{
	const tg::Model &m = L.model;
	L.mesh_uses.assign(m.meshes.size(), 0);
	L.mesh_id.assign(m.meshes.size(), -1);
	L.mesh_inst.assign(m.meshes.size(), 0);
	std::vector<char> seen(m.nodes.size(), 0);
	std::vector<int> stack;
	for (int r : roots)
		if (r >= 0 && (size_t)r < m.nodes.size())
			stack.push_back(r);
	while (!stack.empty()) {
		int ni = stack.back();
		stack.pop_back();
		if (seen[(size_t)ni])
			continue;
		seen[(size_t)ni] = 1;
		const tg::Node &n = m.nodes[(size_t)ni];
		if (n.mesh >= 0 && (size_t)n.mesh < m.meshes.size() && !value_truthy(value_member(n.extras, "portal"))) {
			int acc[3];
			size_t count = 1;
			if (!gpu_instancing(L, ni, acc, &count))
				count = 1;
			L.mesh_uses[(size_t)n.mesh] += count;
		}
		for (int c : n.children)
			if (c >= 0 && (size_t)c < m.nodes.size())
				stack.push_back(c);
	}
	for (size_t k = 0; k < m.meshes.size(); k++)
		L.mesh_inst[k] = L.instancing == GLTF_INSTANCING_ALL    ? L.mesh_uses[k] >= 1
				 : L.instancing == GLTF_INSTANCING_NONE ? 0
									: gltf_mesh_instanced(mesh_triangles(L, (int)k), L.mesh_uses[k]);
}

/* The first perspective camera of the traversal sets the scene's camera. */
ajar_status load_camera_node(Loader &L, int ni, const double world[16])
{
	const tg::Node &n = L.model.nodes[(size_t)ni];
	if ((size_t)n.camera >= L.model.cameras.size())
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: cameras[%d] does not exist (%zu cameras)", ni, n.camera,
			    L.model.cameras.size());
	const tg::Camera &c = L.model.cameras[(size_t)n.camera];
	if (c.type != "perspective") {
		log_msg(AJAR_LOG_INFO, "%s: cameras[%d]: %s camera skipped (only perspective is supported)", L.file,
			n.camera, c.type.c_str());
		return AJAR_OK;
	}
	double yfov = c.perspective.yfov, aspect = c.perspective.aspectRatio;
	if (!(yfov > 0.0 && yfov < 3.14159265358979323846) || !(aspect >= 0.0))
		return fail(L, AJAR_ERROR_BAD_INPUT, "cameras[%d]: yfov %g must be in (0, pi), aspectRatio %g positive",
			    n.camera, yfov, aspect);
	V3 pos = v3((float)world[12], (float)world[13], (float)world[14]);
	V3 fwd = v3((float)-world[8], (float)-world[9], (float)-world[10]);
	V3 up = v3((float)world[4], (float)world[5], (float)world[6]);
	if (scene_set_camera(L.s, pos, fwd, up, (float)yfov, (float)aspect)) {
		std::string msg = ajar_last_error();
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: unusable camera transform (%s)", ni, msg.c_str());
	}
	char where[64];
	snprintf(where, sizeof where, "cameras[%d]", n.camera);
	ajar_status st = read_resolution(L, c.extras, where);
	snprintf(where, sizeof where, "nodes[%d]", ni);
	return st ? st : read_resolution(L, n.extras, where);
}

/* A node's KHR_lights_punctual light: at the node's world position,
 * pointing down its world -Z (scale affects neither the light's range nor
 * its intensity). */
ajar_status load_light_node(Loader &L, int ni, const double world[16])
{
	const tg::Node &n = L.model.nodes[(size_t)ni];
	auto it = n.extensions.find("KHR_lights_punctual");
	if (it == n.extensions.end())
		return AJAR_OK;
	const tg::Value *v = value_member(it->second, "light");
	if (!v || !v->IsNumber())
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: KHR_lights_punctual has no light index", ni);
	double li = v->GetNumberAsDouble();
	if (!(li >= 0.0 && li < (double)L.model.lights.size()) || li != std::floor(li))
		return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: KHR_lights_punctual light %g does not exist (%zu lights)", ni,
			    li, L.model.lights.size());
	const tg::Light &gl = L.model.lights[(size_t)li];
	ajar_light l;
	memset(&l, 0, sizeof l);
	l.color[0] = l.color[1] = l.color[2] = 1.0f; /* the spec's default */
	if (gl.type == "directional")
		l.type = AJAR_LIGHT_DIRECTIONAL;
	else if (gl.type == "point")
		l.type = AJAR_LIGHT_POINT;
	else if (gl.type == "spot")
		l.type = AJAR_LIGHT_SPOT;
	else
		return fail(L, AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[%g]: unknown type '%s'", li, gl.type.c_str());
	if (!gl.color.empty() && gl.color.size() != 3)
		return fail(L, AJAR_ERROR_BAD_INPUT, "KHR_lights_punctual.lights[%g]: color has %zu numbers, expected 3", li,
			    gl.color.size());
	for (size_t k = 0; k < gl.color.size(); k++)
		l.color[k] = (float)gl.color[k];
	l.intensity = (float)gl.intensity;
	l.range = (float)gl.range; /* tinygltf: 0 when absent (infinite) */
	l.inner_cone = (float)gl.spot.innerConeAngle;
	l.outer_cone = (float)gl.spot.outerConeAngle;
	for (int k = 0; k < 3; k++) {
		l.position[k] = (float)world[12 + k];
		l.direction[k] = (float)-world[8 + k];
	}
	char what[96];
	snprintf(what, sizeof what, "nodes[%d]: KHR_lights_punctual.lights[%g]", ni, li);
	return scene_add_light(L.s, what, &l);
}

/* Depth-first, parents before children, in file order, so "the first
 * camera" is well defined. */
ajar_status walk_nodes(Loader &L, const std::vector<int> &roots, const char *roots_what)
{
	const size_t nn = L.model.nodes.size();
	struct Item {
		int node;
		double parent[16];
	};
	std::vector<Item> stack;
	std::vector<char> seen(nn, 0);
	for (size_t r = roots.size(); r-- > 0;) {
		if (roots[r] < 0 || (size_t)roots[r] >= nn)
			return fail(L, AJAR_ERROR_BAD_INPUT, "%s: nodes[%d] does not exist (%zu nodes)", roots_what, roots[r],
				    nn);
		Item it;
		it.node = roots[r];
		gltf_mat_identity(it.parent);
		stack.push_back(it);
	}
	while (!stack.empty()) {
		Item it = stack.back();
		stack.pop_back();
		int ni = it.node;
		if (seen[(size_t)ni])
			return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: reached twice (a node may have only one parent)", ni);
		seen[(size_t)ni] = 1;
		const tg::Node &n = L.model.nodes[(size_t)ni];
		double local[16], world[16];
		ajar_status st = node_local(L, ni, local);
		if (st)
			return st;
		gltf_mat_mul(it.parent, local, world);
		if (n.mesh >= 0 && (st = load_mesh_node(L, ni, world)))
			return st;
		if (n.camera >= 0 && !L.s->has_camera && (st = load_camera_node(L, ni, world)))
			return st;
		if ((st = load_light_node(L, ni, world)))
			return st;
		for (size_t k = n.children.size(); k-- > 0;) {
			int ch = n.children[k];
			if (ch < 0 || (size_t)ch >= nn)
				return fail(L, AJAR_ERROR_BAD_INPUT, "nodes[%d]: child nodes[%d] does not exist (%zu nodes)", ni,
					    ch, nn);
			Item c;
			c.node = ch;
			memcpy(c.parent, world, sizeof world);
			stack.push_back(c);
		}
	}
	return AJAR_OK;
}

/* The whole of an opened regular file (closed here); at most 4 GiB, the
 * most a .glb can hold, so a buffer's size is never what a huge file says. */
ajar_status read_fd(const char *path, int fd, uint64_t size, std::vector<unsigned char> &data)
{
	if (size > 0xffffffffu) {
		close(fd);
		return err_set(AJAR_ERROR_BAD_INPUT, "%s: file larger than 4 GiB", path);
	}
	data.resize((size_t)size);
	size_t got = 0;
	while (got < data.size()) {
		ssize_t k = read(fd, data.data() + got, data.size() - got);
		if (k < 0 && errno == EINTR)
			continue;
		if (k <= 0) {
			int e = errno;
			close(fd);
			return err_set(AJAR_ERROR_IO, "%s: cannot read: %s", path, k < 0 ? strerror(e) : "the file shrank");
		}
		got += (size_t)k;
	}
	close(fd);
	return AJAR_OK;
}

ajar_status read_file(const char *path, std::vector<unsigned char> &data)
{
	int fd;
	uint64_t size = 0;
	ajar_status st = input_open(path, &fd, &size);
	return st ? st : read_fd(path, fd, size, data);
}

ajar_status load(Loader &L)
{
	std::vector<unsigned char> data;
	ajar_status st = read_file(L.file, data);
	if (st)
		return st;
	if (data.size() > 0xffffffffu)
		return fail(L, AJAR_ERROR_BAD_INPUT, "file larger than 4 GiB");

	tg::TinyGLTF loader;
	std::string err, warn;
	bool ok;
	tg::FsCallbacks fs = {fs_exists, fs_expand, fs_read, tg::WriteWholeFile, &L};
	loader.SetFsCallbacks(fs);
	loader.SetImageLoader(load_image, &L);
	if (data.size() >= 4 && memcmp(data.data(), "glTF", 4) == 0)
		ok = loader.LoadBinaryFromMemory(&L.model, &err, &warn, data.data(), (unsigned)data.size(), L.dir);
	else
		ok = loader.LoadASCIIFromString(&L.model, &err, &warn, (const char *)data.data(), (unsigned)data.size(),
						L.dir);
	if (!L.refused.empty())
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s", L.refused.c_str());
	if (!warn.empty())
		log_msg(AJAR_LOG_WARNING, "%s: %s", L.file, one_line(warn).c_str());
	if (!ok)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s", err.empty() ? "cannot parse glTF" : one_line(err).c_str());

	const tg::Model &m = L.model;
	for (const std::string &ext : m.extensionsRequired) {
		if (!gltf_extension_supported(ext.data(), ext.size()))
			return fail(L, AJAR_ERROR_BAD_INPUT, "extensionsRequired: %s is not supported", ext.c_str());
	}
	for (const std::string &ext : m.extensionsUsed) { /* one warning each: none is ignored silently */
		bool known = gltf_extension_supported(ext.data(), ext.size());
		for (const tg::Material &gm : m.materials) /* those load_material names per material */
			known = known || gm.extensions.count(ext);
		if (!known)
			log_msg(AJAR_LOG_WARNING, "%s: extensionsUsed: %s is not supported; ignored", L.file, ext.c_str());
	}

	L.image_textures.assign(m.images.size(), -1);
	L.material_ids.resize(m.materials.size());
	for (size_t i = 0; i < m.materials.size(); i++)
		if ((st = load_material(L, (int)i, &L.material_ids[i])))
			return st;

	std::vector<int> roots;
	const tg::Value *scene_extras = nullptr;
	char where[64] = "nodes";
	if (!m.scenes.empty()) {
		int si = m.defaultScene >= 0 ? m.defaultScene : 0;
		if ((size_t)si >= m.scenes.size())
			return fail(L, AJAR_ERROR_BAD_INPUT, "scene: scenes[%d] does not exist (%zu scenes)", si,
				    m.scenes.size());
		roots = m.scenes[(size_t)si].nodes;
		scene_extras = &m.scenes[(size_t)si].extras;
		snprintf(where, sizeof where, "scenes[%d]", si);
	} else {
		/* No scenes: every node nobody lists as a child is a root. */
		std::vector<char> child(m.nodes.size(), 0);
		for (const tg::Node &n : m.nodes)
			for (int c : n.children)
				if (c >= 0 && (size_t)c < m.nodes.size())
					child[(size_t)c] = 1;
		for (size_t i = 0; i < m.nodes.size(); i++)
			if (!child[i])
				roots.push_back((int)i);
	}
	count_mesh_uses(L, roots);
	if ((st = walk_nodes(L, roots, where)))
		return st;
	if (scene_extras &&
	    ((st = read_resolution(L, *scene_extras, where)) || (st = read_environment(L, *scene_extras, where))))
		return st;
	if (scene_rendered_triangles(L.s) == 0)
		return fail(L, AJAR_ERROR_BAD_INPUT, "%s: no triangles to render%s", where,
			    L.s->nportal_tris ? " (portals do not count)" : "");
	return AJAR_OK;
}

} // namespace

extern "C" ajar_status gltf_load(const char *path, Scene **out) { return gltf_load_with(path, 0, out); }

extern "C" ajar_status gltf_load_with(const char *path, int allow_outside_files, Scene **out)
{
	return gltf_load_instancing(path, allow_outside_files, GLTF_INSTANCING_AUTO, out);
}

extern "C" ajar_status gltf_load_instancing(const char *path, int allow_outside_files, int instancing, Scene **out)
{
	*out = nullptr;
	Scene *s = nullptr;
	ajar_status st = scene_new(path, &s);
	if (st)
		return st;
	try {
		Loader L;
		L.file = path;
		L.s = s;
		const char *slash = strrchr(path, '/');
		L.dir = slash ? std::string(path, (size_t)(slash - path)) : std::string(".");
		if (L.dir.empty())
			L.dir = "/";
		L.allow_outside = allow_outside_files != 0;
		L.instancing = instancing;
		char real[PATH_MAX];
		L.root = realpath(L.dir.c_str(), real) ? real : L.dir;
		st = load(L);
	} catch (const std::bad_alloc &) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
	} catch (const std::exception &e) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: %s", path, e.what());
	} catch (...) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: unexpected error while loading", path);
	}
	if (st) {
		scene_free(s);
		return st;
	}
	*out = s;
	return AJAR_OK;
}
