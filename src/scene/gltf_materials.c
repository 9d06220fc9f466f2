/* gltf_materials.c — glTF materials as scene materials: the metallic-
 * roughness core with its textures, and the extensions Ajar reads
 * (emissive strength, IOR, specular, transmission, volume, sheen, clear
 * coat, anisotropy; src/scene/README.md). Members it does not read get one
 * warning each naming the material, as does every other extension on it. */
#include "scene/gltf_loader.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/gltf_parts.h"

/* extensions[ext][key] as a number in [lo, hi], or `def` if absent. */
static ajar_status ext_number(const GltfLoader *L, int mi, const GltfValue *exts, const char *ext, const char *key,
			      double def, double lo, double hi, double *out)
{
	*out = def;
	const GltfValue *v = gltf_member(gltf_member(exts, ext), key);
	if (!v)
		return AJAR_OK;
	if (v->type != GLTF_VALUE_NUMBER || !(v->number >= lo && v->number <= hi))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s must be a number in [%g, %g]", mi, ext, key,
				 lo, hi);
	*out = v->number;
	return AJAR_OK;
}

/* A member of extensions[ext] that Ajar does not read (a texture, a tint):
 * one warning naming it and what is used instead. */
static void ext_unread(const GltfLoader *L, int mi, const GltfValue *exts, const char *ext, const char *key,
		       const char *instead)
{
	if (gltf_member(gltf_member(exts, ext), key))
		log_msg(AJAR_LOG_WARNING, "%s: materials[%d]: %s.%s is not supported; %s", L->file, mi, ext, key, instead);
}

/* extensions[ext][key] as a colour: 3 finite numbers in [0, hi], or `def`
 * if absent. */
static ajar_status ext_color(const GltfLoader *L, int mi, const GltfValue *exts, const char *ext, const char *key,
			     V3 def, double hi, V3 *out)
{
	*out = def;
	const GltfValue *c = gltf_member(gltf_member(exts, ext), key);
	if (!c)
		return AJAR_OK;
	double v[3];
	int ok = c->type == GLTF_VALUE_ARRAY && c->count == 3;
	for (int k = 0; ok && k < 3; k++) {
		const GltfValue *x = gltf_item(c, (size_t)k);
		ok = x->type == GLTF_VALUE_NUMBER;
		v[k] = ok ? x->number : 0.0;
		ok = ok && v[k] >= 0.0 && v[k] <= hi;
	}
	if (!ok)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s.%s must be 3 numbers in [0, %g]", mi, ext, key,
				 hi);
	*out = v3((float)v[0], (float)v[1], (float)v[2]);
	return AJAR_OK;
}

/* KHR_materials_volume: a thickness above 0 makes the material a solid
 * that transmission refracts into (MATERIAL_VOLUME), absorbing by
 * sigma = -ln(attenuationColor) / attenuationDistance inside; without it
 * (or with thickness 0) transmission is thin-walled, as glTF defines. */
static ajar_status load_volume(const GltfLoader *L, int mi, const GltfValue *exts, Material *m)
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
	const GltfValue *c = gltf_member(gltf_member(exts, "KHR_materials_volume"), "attenuationColor");
	double col[3] = {1.0, 1.0, 1.0};
	if (c) {
		if (c->type != GLTF_VALUE_ARRAY || c->count != 3)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
					 "materials[%d]: KHR_materials_volume.attenuationColor needs 3 numbers", mi);
		for (int k = 0; k < 3; k++) {
			const GltfValue *x = gltf_item(c, (size_t)k);
			if (x->type != GLTF_VALUE_NUMBER || !(x->number >= 0.0 && x->number <= 1.0))
				return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
						 "materials[%d]: KHR_materials_volume.attenuationColor must be in [0, 1]", mi);
			col[k] = x->number;
		}
	}
	if (!(distance > 0.0))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
				 "materials[%d]: KHR_materials_volume.attenuationDistance must be above 0", mi);
	float sigma[3];
	for (int k = 0; k < 3; k++) /* a colour of 0 absorbs everything: a large finite coefficient */
		sigma[k] = isinf(distance) ? 0.0f : (float)fmin(-log(fmax(col[k], 1e-30)) / distance, 1e30);
	m->sigma = v3(sigma[0], sigma[1], sigma[2]);
	return AJAR_OK;
}

/* KHR_materials_specular (factor and colour with their textures), _sheen,
 * _clearcoat and _anisotropy (kernels/material/bsdf.h, "Layers"). */
static ajar_status load_material_layers(GltfLoader *L, int mi, const GltfValue *exts, Material *m)
{
	ajar_status st;
	double sheen_r, cc, cc_r, aniso, rot;
	V3 tint, sheen;
	int spec_t, tint_t, sheen_t, sheen_rt, cc_t, cc_rt, cc_nt, aniso_t;
	if ((st = ext_color(L, mi, exts, "KHR_materials_specular", "specularColorFactor", v3(1.0f, 1.0f, 1.0f), 1e30,
			    &tint)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_specular", "specularTexture", &spec_t)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_specular", "specularColorTexture", &tint_t)) ||
	    (st = ext_color(L, mi, exts, "KHR_materials_sheen", "sheenColorFactor", v3(0.0f, 0.0f, 0.0f), 1.0, &sheen)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_sheen", "sheenRoughnessFactor", 0.0, 0.0, 1.0, &sheen_r)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_sheen", "sheenColorTexture", &sheen_t)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_sheen", "sheenRoughnessTexture", &sheen_rt)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_clearcoat", "clearcoatFactor", 0.0, 0.0, 1.0, &cc)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_clearcoat", "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, &cc_r)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatTexture", &cc_t)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatRoughnessTexture", &cc_rt)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_clearcoat", "clearcoatNormalTexture", &cc_nt)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_anisotropy", "anisotropyStrength", 0.0, 0.0, 1.0, &aniso)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_anisotropy", "anisotropyRotation", 0.0, -1e6, 1e6, &rot)) ||
	    (st = gltf_ext_texture(L, mi, exts, "KHR_materials_anisotropy", "anisotropyTexture", &aniso_t)))
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
	const GltfValue *info = gltf_member(gltf_member(exts, "KHR_materials_clearcoat"), "clearcoatNormalTexture");
	const GltfValue *scale = gltf_member(info, "scale");
	if (scale) {
		if (scale->type != GLTF_VALUE_NUMBER || !isfinite(scale->number))
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT,
					 "materials[%d]: clearcoatNormalTexture.scale is not a finite number", mi);
		m->clearcoat_normal_scale = (float)scale->number;
	}
	m->anisotropy = (float)aniso;
	m->anisotropy_rotation = (float)remainder(rot, 2.0 * M_PI); /* [-pi, pi] */
	m->anisotropy_tex = aniso_t + 1;
	if (aniso_t >= 0 && !(aniso > 0.0))
		m->anisotropy_tex = 0; /* the texture's B multiplies a strength of 0 */
	for (size_t e = 0; e < exts->count; e++) {
		GltfString name = exts->keys[e];
		if (!gltf_material_extension_read(name.s, name.len))
			log_msg(AJAR_LOG_WARNING, "%s: materials[%d] (%s): %s is not supported; ignored", L->file, mi,
				L->doc->materials[mi].name.s, name.s);
	}
	return AJAR_OK;
}

static ajar_status in_unit(const GltfLoader *L, int mi, const char *name, double v)
{
	if (!(v >= 0.0 && v <= 1.0))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: %s %g is not in [0, 1]", mi, name, v);
	return AJAR_OK;
}

/* The metallic-roughness core: factors, emission, alpha. */
static ajar_status load_core(const GltfLoader *L, int mi, Material *m)
{
	const GltfMaterial *gm = &L->doc->materials[mi];
	const GltfValue *exts = &gm->extensions;
	ajar_status st = AJAR_OK;
	if (gm->base_color.n != 4)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: baseColorFactor has %zu numbers, expected 4", mi,
				 gm->base_color.n);
	const double *bc = gm->base_color.v;
	for (int c = 0; c < 4 && !st; c++)
		st = in_unit(L, mi, "baseColorFactor", bc[c]);
	if (!st)
		st = in_unit(L, mi, "metallicFactor", gm->metallic);
	if (!st)
		st = in_unit(L, mi, "roughnessFactor", gm->roughness);
	if (st)
		return st;
	m->base_color = v3((float)bc[0], (float)bc[1], (float)bc[2]);
	m->metallic = (float)gm->metallic;
	m->roughness = (float)gm->roughness;
	m->base_tex = -1;

	double strength, transmission, ior, specular;
	if ((st = ext_number(L, mi, exts, "KHR_materials_emissive_strength", "emissiveStrength", 1.0, 0.0, 1e30,
			     &strength)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_transmission", "transmissionFactor", 0.0, 0.0, 1.0,
			     &transmission)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_ior", "ior", 1.5, 1.0, 10.0, &ior)) ||
	    (st = ext_number(L, mi, exts, "KHR_materials_specular", "specularFactor", 1.0, 0.0, 1.0, &specular)))
		return st;
	if (gm->emissive.n) {
		const double *e = gm->emissive.v;
		if (gm->emissive.n != 3)
			return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: emissiveFactor has %zu numbers, expected 3",
					 mi, gm->emissive.n);
		for (int c = 0; c < 3 && !st; c++)
			st = in_unit(L, mi, "emissiveFactor", e[c]);
		if (st)
			return st;
		m->emission = v3((float)(e[0] * strength), (float)(e[1] * strength), (float)(e[2] * strength));
	}
	m->transmission = (float)transmission;
	m->ior = (float)ior;
	m->specular = (float)specular;
	m->flags = gm->double_sided ? MATERIAL_DOUBLE_SIDED : 0;
	m->alpha_cutoff = (float)gm->alpha_cutoff;
	m->base_alpha = (float)bc[3];
	if (gltf_string_is(gm->alpha_mode, "MASK"))
		m->flags |= MATERIAL_ALPHA_MASK;
	else if (gltf_string_is(gm->alpha_mode, "BLEND"))
		m->flags |= MATERIAL_ALPHA_BLEND;
	else if (!gltf_string_is(gm->alpha_mode, "OPAQUE") && gm->alpha_mode.len)
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: alphaMode \"%s\" is not OPAQUE, MASK or BLEND",
				 mi, gm->alpha_mode.s);
	return AJAR_OK;
}

static ajar_status load_material(GltfLoader *L, int mi, uint32_t *id)
{
	const GltfMaterial *gm = &L->doc->materials[mi];
	Material m;
	memset(&m, 0, sizeof m);
	ajar_status st = load_core(L, mi, &m);
	if (st)
		return st;
	int base = -1, mr = -1, em = -1;
	const GltfTextureInfo *bt = &gm->base_color_texture, *mt = &gm->metallic_roughness_texture,
			      *et = &gm->emissive_texture, *nt = &gm->normal_texture;
	if ((st = gltf_texture_use(L, mi, "baseColorTexture", bt->index, bt->texcoord, &bt->extensions, &base)) ||
	    (st = gltf_texture_use(L, mi, "metallicRoughnessTexture", mt->index, mt->texcoord, &mt->extensions, &mr)) ||
	    (st = gltf_texture_use(L, mi, "emissiveTexture", et->index, et->texcoord, &et->extensions, &em)))
		return st;
	m.base_tex = base;
	m.mr_tex = mr + 1;
	m.emissive_tex = em + 1;
	int nrm = -1;
	if ((st = gltf_texture_use(L, mi, "normalTexture", nt->index, nt->texcoord, &nt->extensions, &nrm)))
		return st;
	if (!isfinite(nt->scale))
		return gltf_fail(L, AJAR_ERROR_BAD_INPUT, "materials[%d]: normalTexture.scale is not finite", mi);
	m.normal_tex = nrm + 1;
	m.normal_scale = (float)nt->scale;
	int tr = -1;
	if ((st = gltf_ext_texture(L, mi, &gm->extensions, "KHR_materials_transmission", "transmissionTexture", &tr)) ||
	    (st = load_volume(L, mi, &gm->extensions, &m)))
		return st;
	m.transmission_tex = tr + 1;
	if ((st = load_material_layers(L, mi, &gm->extensions, &m)))
		return st;
	return scene_add_material(L->s, &m, id);
}

ajar_status gltf_load_materials(GltfLoader *L)
{
	for (size_t i = 0; i < L->doc->nmaterials; i++) {
		ajar_status st = load_material(L, (int)i, &L->material_ids[i]);
		if (st)
			return st;
	}
	return AJAR_OK;
}

/* The glTF default material (spec 3.9.6): white, metallic 1, roughness 1. */
ajar_status gltf_default_material(GltfLoader *L, uint32_t *id)
{
	if (L->default_material < 0) {
		Material m;
		memset(&m, 0, sizeof m);
		m.base_color = v3(1.0f, 1.0f, 1.0f);
		m.base_tex = -1;
		m.metallic = 1.0f;
		m.roughness = 1.0f;
		m.ior = 1.5f;
		m.specular = 1.0f;
		m.alpha_cutoff = 0.5f;
		uint32_t mid;
		ajar_status st = scene_add_material(L->s, &m, &mid);
		if (st)
			return st;
		L->default_material = (int)mid;
	}
	*id = (uint32_t)L->default_material;
	return AJAR_OK;
}
