/* gltf.cpp — tinygltf's half of the glTF 2.0 loader, the only C++ in Ajar:
 * it reads the file, parses it with tinygltf (our file-system callbacks
 * keep every file the scene names inside its folder, our image loader
 * decodes textures) and copies the Model into a plain C document
 * (gltf_doc.h), which the C files of gltf_loader.h turn into a Scene. No
 * exception leaves it (gltf_doc_load catches everything and returns a
 * status), and no tinygltf type leaves it: the document points into the
 * Model, which it keeps until gltf_doc_free, so buffers are never copied.
 *
 * tinygltf is used as Debian builds it (libtinygltf.so with its file system
 * and stb_image loaders compiled in), so the header is included plainly,
 * without TINYGLTF_IMPLEMENTATION or any option that changes its classes.
 * tinygltf checks JSON syntax and loads buffers and images; it does not
 * check that accessors and buffer views stay inside their data: the C
 * readers check every range. */
#include <tiny_gltf.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "image/texture_file.h"
#include "scene/gltf_doc.h"
#include "scene/gltf_parts.h"

/* gltf_parts.h's codes are glTF's, as tinygltf's are. */
static_assert(GLTF_BYTE == TINYGLTF_COMPONENT_TYPE_BYTE && GLTF_UNSIGNED_BYTE == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
		      GLTF_SHORT == TINYGLTF_COMPONENT_TYPE_SHORT &&
		      GLTF_UNSIGNED_SHORT == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
		      GLTF_UNSIGNED_INT == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && GLTF_FLOAT == TINYGLTF_COMPONENT_TYPE_FLOAT &&
		      GLTF_VEC2 == TINYGLTF_TYPE_VEC2 && GLTF_VEC3 == TINYGLTF_TYPE_VEC3 && GLTF_VEC4 == TINYGLTF_TYPE_VEC4 &&
		      GLTF_SCALAR == TINYGLTF_TYPE_SCALAR && GLTF_MODE_TRIANGLES == TINYGLTF_MODE_TRIANGLES &&
		      GLTF_MODE_TRIANGLE_STRIP == TINYGLTF_MODE_TRIANGLE_STRIP &&
		      GLTF_MODE_TRIANGLE_FAN == TINYGLTF_MODE_TRIANGLE_FAN &&
		      GLTF_FILTER_NEAREST == TINYGLTF_TEXTURE_FILTER_NEAREST &&
		      GLTF_WRAP_CLAMP_TO_EDGE == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE &&
		      GLTF_WRAP_MIRRORED_REPEAT == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT,
	      "glTF's codes");

namespace {

namespace tg = tinygltf;

/* The parse's context, for tinygltf's callbacks. */
struct Loader {
	const char *file;
	std::string dir;
	tg::Model *model;
	bool allow_outside = false; /* files outside the scene's folder may be read */
	std::string root;           /* the scene's folder, symbolic links resolved */
	std::string refused;        /* the first refusal of a file the scene names */
};

/* "file: why" as the load's error, why cut as the C loader's messages are
 * (gltf_fail). */
ajar_status fail(const Loader &L, const std::string &why)
{
	return err_set(AJAR_ERROR_BAD_INPUT, "%s: %.1535s", L.file, why.c_str());
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

/* Whether `path` (which exists) may be read (gltf_confined); the first
 * refusal is kept in L.refused. `uri` is how the scene named it. */
bool confined(Loader &L, const std::string &path, const std::string &uri)
{
	char why[GLTF_WHY_SIZE];
	bool inside = gltf_confined(L.root.c_str(), L.allow_outside, path.c_str(), uri.c_str(), why, sizeof why);
	if (!inside && why[0] && L.refused.empty())
		L.refused = why;
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

ajar_status read_file(const char *path, std::vector<unsigned char> &data);

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
	if (read_file(path.c_str(), *out) != AJAR_OK) {
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
	const tg::Model &m = *((const Loader *)user)->model;
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

/* The whole of a file the scene names (gltf_files.c). */
ajar_status read_file(const char *path, std::vector<unsigned char> &data)
{
	int fd;
	size_t size = 0;
	ajar_status st = gltf_file_open(path, &fd, &size);
	if (st)
		return st;
	try {
		data.resize(size);
	} catch (...) {
		close(fd);
		throw;
	}
	return gltf_file_read(path, fd, data.data(), size);
}

/* ---- The document -----------------------------------------------------------
 * The Model and what the C structs point to: arrays of the mirror's
 * structs, and the key-value trees' items and keys. */
struct DocStore : GltfDoc {
	tg::Model model;
	std::vector<GltfBuffer> buffers;
	std::vector<GltfBufferView> views;
	std::vector<GltfAccessor> accessors;
	std::vector<GltfImage> images;
	std::vector<GltfSampler> samplers;
	std::vector<GltfTexture> textures;
	std::vector<GltfMaterial> materials;
	std::vector<std::vector<GltfAttribute>> attributes;
	std::vector<std::vector<GltfPrimitive>> primitives;
	std::vector<GltfMesh> meshes;
	std::vector<GltfNode> nodes;
	std::vector<GltfCamera> cameras;
	std::vector<GltfLight> lights;
	std::vector<GltfScene> scenes;
	std::vector<GltfString> required, used;
	std::vector<std::unique_ptr<GltfValue[]>> items;
	std::vector<std::unique_ptr<GltfString[]>> keys;
};

GltfString str(const std::string &s) { return GltfString{s.c_str(), s.size()}; }
GltfNumbers numbers(const std::vector<double> &v) { return GltfNumbers{v.data(), v.size()}; }
GltfInts ints(const std::vector<int> &v) { return GltfInts{v.data(), v.size()}; }

/* The members of an object (an ExtensionMap is one) in map order. */
GltfValue object(DocStore &d, const std::map<std::string, tg::Value> &members);

GltfValue value(DocStore &d, const tg::Value &v)
{
	GltfValue out;
	memset(&out, 0, sizeof out);
	out.string = GltfString{"", 0};
	if (v.IsBool()) {
		out.type = GLTF_VALUE_BOOL;
		out.boolean = v.Get<bool>();
	} else if (v.IsNumber()) {
		out.type = GLTF_VALUE_NUMBER;
		out.number = v.GetNumberAsDouble();
	} else if (v.IsString()) {
		out.type = GLTF_VALUE_STRING;
		out.string = str(v.Get<std::string>());
	} else if (v.IsArray()) {
		const tg::Value::Array &a = v.Get<tg::Value::Array>();
		std::unique_ptr<GltfValue[]> items(new GltfValue[a.size()]);
		for (size_t i = 0; i < a.size(); i++)
			items[i] = value(d, a[i]);
		out.type = GLTF_VALUE_ARRAY;
		out.count = a.size();
		out.items = items.get();
		d.items.push_back(std::move(items));
	} else if (v.IsObject()) {
		out = object(d, v.Get<tg::Value::Object>());
	}
	return out;
}

GltfValue object(DocStore &d, const std::map<std::string, tg::Value> &members)
{
	GltfValue out;
	memset(&out, 0, sizeof out);
	std::unique_ptr<GltfValue[]> items(new GltfValue[members.size()]);
	std::unique_ptr<GltfString[]> keys(new GltfString[members.size()]);
	size_t i = 0;
	for (const auto &m : members) {
		keys[i] = str(m.first);
		items[i++] = value(d, m.second);
	}
	out.type = GLTF_VALUE_OBJECT;
	out.count = members.size();
	out.items = items.get();
	out.keys = keys.get();
	d.items.push_back(std::move(items));
	d.keys.push_back(std::move(keys));
	return out;
}

GltfAccessor accessor(const tg::Accessor &a)
{
	const auto &sp = a.sparse;
	return GltfAccessor{a.bufferView,	     a.byteOffset,	     a.componentType,
			    a.normalized,	     a.count,		     a.type,
			    sp.isSparse,	     sp.count,		     sp.indices.bufferView,
			    sp.indices.byteOffset, sp.indices.componentType, sp.values.bufferView,
			    sp.values.byteOffset};
}

GltfTextureInfo texture_info(DocStore &d, int index, int texcoord, double scale, const tg::ExtensionMap &exts)
{
	return GltfTextureInfo{index, texcoord, scale, object(d, exts)};
}

GltfMaterial material(DocStore &d, const tg::Material &m)
{
	const tg::PbrMetallicRoughness &pbr = m.pbrMetallicRoughness;
	const tg::TextureInfo &bt = pbr.baseColorTexture, &mt = pbr.metallicRoughnessTexture, &et = m.emissiveTexture;
	const tg::NormalTextureInfo &nt = m.normalTexture;
	return GltfMaterial{str(m.name), numbers(pbr.baseColorFactor), numbers(m.emissiveFactor), pbr.metallicFactor,
			    pbr.roughnessFactor, m.alphaCutoff, m.doubleSided, str(m.alphaMode),
			    texture_info(d, bt.index, bt.texCoord, 1.0, bt.extensions),
			    texture_info(d, mt.index, mt.texCoord, 1.0, mt.extensions),
			    texture_info(d, et.index, et.texCoord, 1.0, et.extensions),
			    texture_info(d, nt.index, nt.texCoord, nt.scale, nt.extensions), object(d, m.extensions)};
}

void copy_meshes(DocStore &d)
{
	for (const tg::Mesh &mesh : d.model.meshes) {
		std::vector<GltfPrimitive> prims;
		for (const tg::Primitive &p : mesh.primitives) {
			std::vector<GltfAttribute> attrs;
			for (const auto &a : p.attributes)
				attrs.push_back(GltfAttribute{str(a.first), a.second});
			d.attributes.push_back(std::move(attrs));
			prims.push_back(GltfPrimitive{p.mode, p.indices, p.material, d.attributes.back().size(),
						      d.attributes.back().data()});
		}
		d.primitives.push_back(std::move(prims));
		d.meshes.push_back(GltfMesh{d.primitives.back().size(), d.primitives.back().data()});
	}
}

/* The Model's parts the loader reads, as gltf_doc.h's structs. */
void copy_model(DocStore &d)
{
	const tg::Model &m = d.model;
	for (const tg::Buffer &b : m.buffers)
		d.buffers.push_back(GltfBuffer{b.data.data(), b.data.size()});
	for (const tg::BufferView &v : m.bufferViews)
		d.views.push_back(GltfBufferView{v.buffer, v.byteOffset, v.byteLength, v.byteStride});
	for (const tg::Accessor &a : m.accessors)
		d.accessors.push_back(accessor(a));
	for (const tg::Image &im : m.images)
		d.images.push_back(GltfImage{im.width, im.height, im.component, im.bits, im.image.data(), im.image.size()});
	for (const tg::Sampler &s : m.samplers)
		d.samplers.push_back(GltfSampler{s.wrapS, s.wrapT, s.magFilter});
	for (const tg::Texture &t : m.textures)
		d.textures.push_back(GltfTexture{t.source, t.sampler});
	for (const tg::Material &mat : m.materials)
		d.materials.push_back(material(d, mat));
	copy_meshes(d);
	for (const tg::Node &n : m.nodes)
		d.nodes.push_back(GltfNode{n.mesh, n.camera, ints(n.children), numbers(n.matrix), numbers(n.translation),
					   numbers(n.rotation), numbers(n.scale), value(d, n.extras),
					   object(d, n.extensions)});
	for (const tg::Camera &c : m.cameras)
		d.cameras.push_back(
			GltfCamera{str(c.type), c.perspective.yfov, c.perspective.aspectRatio, value(d, c.extras)});
	for (const tg::Light &l : m.lights)
		d.lights.push_back(GltfLight{str(l.type), numbers(l.color), l.intensity, l.range, l.spot.innerConeAngle,
					     l.spot.outerConeAngle});
	for (const tg::Scene &s : m.scenes)
		d.scenes.push_back(GltfScene{ints(s.nodes), value(d, s.extras)});
	for (const std::string &e : m.extensionsRequired)
		d.required.push_back(str(e));
	for (const std::string &e : m.extensionsUsed)
		d.used.push_back(str(e));

	GltfDoc &c = d;
	c = GltfDoc{d.buffers.size(),   d.views.size(),    d.accessors.size(), d.images.size(), d.samplers.size(),
		    d.textures.size(),  d.materials.size(), d.meshes.size(),    d.nodes.size(),  d.cameras.size(),
		    d.lights.size(),    d.scenes.size(),   d.buffers.data(),   d.views.data(),  d.accessors.data(),
		    d.images.data(),    d.samplers.data(), d.textures.data(),  d.materials.data(), d.meshes.data(),
		    d.nodes.data(),     d.cameras.data(),  d.lights.data(),    d.scenes.data(), m.defaultScene,
		    d.required.size(),  d.used.size(),     d.required.data(),  d.used.data()};
}

/* Parses L.file into d.model: tinygltf with our callbacks; the first
 * refusal of a file the scene names is the error. */
ajar_status parse(Loader &L, DocStore &d)
{
	std::vector<unsigned char> data;
	ajar_status st = read_file(L.file, data);
	if (st)
		return st;

	tg::TinyGLTF loader;
	std::string err, warn;
	bool ok;
	tg::FsCallbacks fs = {fs_exists, fs_expand, fs_read, tg::WriteWholeFile, &L};
	loader.SetFsCallbacks(fs);
	loader.SetImageLoader(load_image, &L);
	if (data.size() >= 4 && memcmp(data.data(), "glTF", 4) == 0)
		ok = loader.LoadBinaryFromMemory(&d.model, &err, &warn, data.data(), (unsigned)data.size(), L.dir);
	else
		ok = loader.LoadASCIIFromString(&d.model, &err, &warn, (const char *)data.data(), (unsigned)data.size(),
						L.dir);
	if (!L.refused.empty())
		return fail(L, L.refused);
	if (!warn.empty())
		log_msg(AJAR_LOG_WARNING, "%s: %s", L.file, one_line(warn).c_str());
	if (!ok)
		return fail(L, err.empty() ? "cannot parse glTF" : one_line(err));
	copy_model(d);
	return AJAR_OK;
}

} // namespace

extern "C" ajar_status gltf_doc_load(const char *file, const char *dir, const char *root, int allow_outside,
				     GltfDoc **out)
{
	*out = nullptr;
	ajar_status st;
	DocStore *d = nullptr;
	try {
		d = new DocStore();
		Loader L;
		L.file = file;
		L.dir = dir;
		L.model = &d->model;
		L.allow_outside = allow_outside != 0;
		L.root = root;
		st = parse(L, *d);
	} catch (const std::bad_alloc &) {
		st = err_set(AJAR_ERROR_OUT_OF_MEMORY, "%s: out of memory", file);
	} catch (const std::exception &e) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: %s", file, e.what());
	} catch (...) {
		st = err_set(AJAR_ERROR_BAD_INPUT, "%s: unexpected error while loading", file);
	}
	if (st) {
		delete d;
		return st;
	}
	*out = d;
	return AJAR_OK;
}

extern "C" void gltf_doc_free(GltfDoc *doc) { delete static_cast<DocStore *>(doc); }
