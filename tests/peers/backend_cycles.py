"""backend_cycles.py — the scene in Blender Cycles (bpy), CPU path tracing.

The scene is built from scene.py's triangles, not with Blender's glTF
importer (which neither sets the camera nor keeps flat normals): one flat
shaded mesh per material with a Diffuse BSDF (roughness 0: Lambertian,
two-sided like Ajar's). Emission is one-sided like Ajar's: the Emission
strength is multiplied by (1 - Backfacing), and the material's emission
sampling is FRONT. The world is the uniform environment (black if none), or
the sky image: an Environment Texture with "Closest" interpolation (Ajar's
lookup is nearest-texel), fed the world direction through a Mapping node
with Euler rotation (90, 0, -(90 + rotation)) degrees. The scene is built
in glTF's axes (+Y up), so the X turn first takes the direction to
Blender's (x, -z, y), where Cycles' equirectangular lookup
u = 0.5 - atan2(y, x) / 2 pi is Ajar's u = 0.5 + atan2(x, -z) / 2 pi turned
by -90 degrees about Z, and the sky's rotation about glTF +Y is one about
Blender +Z, the lookup turning the other way (checked with a sky of
numbered columns seen straight on, and by the converged means). Its negative pixels are clamped to 0,
as Ajar does. KHR_lights_punctual lights become Blender lamps with the
importer's "Standard" units: sun strength = lux / 683 W/m^2, point and
spot power = candela x 4 pi / 683 W, spot size = 2 x outer cone angle,
blend = 1 - inner / outer, and no soft radius or sun disk
(shadow_soft_size = 0, angle = 0).
A smooth thin-walled pane (scene.py, is_pane) is glTF's thin model exactly:
a Mix Shader of a Transparent BSDF (colour = base colour x transmission:
straight through, weight (1 - F) base) and a sharp Glossy BSDF (white, GGX,
roughness 0: a mirror of weight F), the factor a Fresnel node. That node
takes 1 / IOR on back faces (an interface into the denser side, with total
reflection past 41.8 degrees), so its IOR input is ior on front faces and
1 / ior on back faces (Backfacing): both sides then see F(ior) of the same
|cos|, as Ajar does. Transparent surfaces pass shadow rays multiplied by
their transparency (Cycles' transparent shadows), so next-event estimation
through the pane carries (1 - F) base as Ajar's connections do; transparent
bounces are counted apart from max_bounces (transparent_max_bounces = the
same D - 2) and the pane's mirror is a glossy bounce.
With --integrator noportal the scene has no portal; otherwise every Ajar
portal quad becomes a Cycles portal: an area light with is_portal set, of
the quad's size, emitting into the room. With --integrator principled
(tests/peers/energy.py) a material that is not Lambertian gets a Principled
BSDF with its base colour, metallic, roughness, IOR and Specular IOR Level
0.5 x specularFactor (0.5 leaves the IOR's Fresnel as it is), as Blender's
glTF importer builds it; portals stay.

Matching (see tests/peers/README.md): max_bounces = D - 2 for Ajar's and
Mitsuba's max depth D (Cycles counts bounces after the first hit, and the
last segment to a light does not count), no clamping (sample_clamp_* 0), no
light threshold, no adaptive sampling, no denoising, the 1-pixel box filter,
Raw view transform and 32-bit float EXR output. Cycles' own Russian roulette
(unbiased) stays. Equal time: cycles.time_limit; the samples reached are
read from the render statistics.
"""
import math
import os
import re
import tempfile
import time

import numpy as np


def make_mesh(bpy, name, v, f):
	me = bpy.data.meshes.new(name)
	me.vertices.add(len(v))
	me.vertices.foreach_set("co", np.asarray(v, dtype=np.float32).ravel())
	me.loops.add(3 * len(f))
	me.loops.foreach_set("vertex_index", np.asarray(f, dtype=np.int32).ravel())
	me.polygons.add(len(f))
	me.polygons.foreach_set("loop_start", np.arange(0, 3 * len(f), 3, dtype=np.int32))
	me.update(calc_edges=True)
	me.polygons.foreach_set("use_smooth", np.zeros(len(f), dtype=bool))
	me.update()
	return me


def make_pane(bpy, name, tint, ior):
	"""The thin pane (see the module comment)."""
	mat = bpy.data.materials.new(name)
	mat.use_nodes = True
	nt = mat.node_tree
	for n in list(nt.nodes):
		nt.nodes.remove(n)
	out = nt.nodes.new("ShaderNodeOutputMaterial")
	tr = nt.nodes.new("ShaderNodeBsdfTransparent")
	tr.inputs["Color"].default_value = (*[float(x) for x in tint], 1.0)
	gl = nt.nodes.new("ShaderNodeBsdfGlossy")
	gl.distribution = "GGX"
	gl.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
	gl.inputs["Roughness"].default_value = 0.0
	geo = nt.nodes.new("ShaderNodeNewGeometry")
	eta = nt.nodes.new("ShaderNodeMath")
	eta.operation = "MULTIPLY_ADD"  # backfacing x (1/ior - ior) + ior
	nt.links.new(geo.outputs["Backfacing"], eta.inputs[0])
	eta.inputs[1].default_value = 1.0 / ior - ior
	eta.inputs[2].default_value = ior
	fr = nt.nodes.new("ShaderNodeFresnel")
	nt.links.new(eta.outputs["Value"], fr.inputs["IOR"])
	mix = nt.nodes.new("ShaderNodeMixShader")
	nt.links.new(fr.outputs["Fac"], mix.inputs["Fac"])
	nt.links.new(tr.outputs["BSDF"], mix.inputs[1])
	nt.links.new(gl.outputs["BSDF"], mix.inputs[2])
	nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
	mat.cycles.emission_sampling = "NONE"
	return mat


def make_material(bpy, name, base, emission, pbr=None):
	mat = bpy.data.materials.new(name)
	mat.use_nodes = True
	nt = mat.node_tree
	for n in list(nt.nodes):
		nt.nodes.remove(n)
	out = nt.nodes.new("ShaderNodeOutputMaterial")
	if pbr is None:
		dif = nt.nodes.new("ShaderNodeBsdfDiffuse")
		dif.inputs["Color"].default_value = (*[float(x) for x in base], 1.0)
		dif.inputs["Roughness"].default_value = 0.0
		shader = dif.outputs["BSDF"]
	else:
		pr = nt.nodes.new("ShaderNodeBsdfPrincipled")
		pr.inputs["Base Color"].default_value = (*[float(x) for x in base], 1.0)
		pr.inputs["Metallic"].default_value = float(pbr["metallic"])
		pr.inputs["Roughness"].default_value = float(pbr["roughness"])
		pr.inputs["IOR"].default_value = float(pbr["ior"])
		pr.inputs["Specular IOR Level"].default_value = 0.5 * float(pbr["specular"])
		pr.inputs["Emission Strength"].default_value = 0.0
		if "Diffuse Roughness" in pr.inputs:  # 0: Lambertian, like Ajar's base
			pr.inputs["Diffuse Roughness"].default_value = 0.0
		shader = pr.outputs["BSDF"]
	s = float(max(emission))
	if s > 0:
		em = nt.nodes.new("ShaderNodeEmission")
		em.inputs["Color"].default_value = (*[float(x) / s for x in emission], 1.0)
		geo = nt.nodes.new("ShaderNodeNewGeometry")
		front = nt.nodes.new("ShaderNodeMath")
		front.operation = "MULTIPLY_ADD"  # backfacing x (-s) + s
		nt.links.new(geo.outputs["Backfacing"], front.inputs[0])
		front.inputs[1].default_value = -s
		front.inputs[2].default_value = s
		nt.links.new(front.outputs["Value"], em.inputs["Strength"])
		add = nt.nodes.new("ShaderNodeAddShader")
		nt.links.new(shader, add.inputs[0])
		nt.links.new(em.outputs["Emission"], add.inputs[1])
		shader = add.outputs["Shader"]
		mat.cycles.emission_sampling = "FRONT"
	else:
		mat.cycles.emission_sampling = "NONE"
	nt.links.new(shader, out.inputs["Surface"])
	return mat


def frame_matrix(mathutils, x, y, z, origin):
	m = mathutils.Matrix.Identity(4)
	for r in range(3):
		m[r][0], m[r][1], m[r][2], m[r][3] = float(x[r]), float(y[r]), float(z[r]), float(origin[r])
	return m


def sky_world(bpy, nt, bg, sky):
	img = bpy.data.images.load(sky["path"])
	img.colorspace_settings.is_data = True  # the file's numbers, no colour conversion
	px = np.empty(img.size[0] * img.size[1] * img.channels, dtype=np.float32)
	img.pixels.foreach_get(px)
	if (px < 0).any():
		img.pixels.foreach_set(np.maximum(px, 0.0))
		img.update()
	tc = nt.nodes.new("ShaderNodeTexCoord")
	mp = nt.nodes.new("ShaderNodeMapping")
	mp.vector_type = "POINT"
	# Euler XYZ: the X turn applies first.
	mp.inputs["Rotation"].default_value = (math.radians(90.0), 0.0, math.radians(-90.0 - sky["rotation"]))
	et = nt.nodes.new("ShaderNodeTexEnvironment")
	et.image = img
	et.interpolation = "Closest"
	et.projection = "EQUIRECTANGULAR"
	nt.links.new(tc.outputs["Generated"], mp.inputs["Vector"])
	nt.links.new(mp.outputs["Vector"], et.inputs["Vector"])
	nt.links.new(et.outputs["Color"], bg.inputs["Color"])
	bg.inputs["Strength"].default_value = float(sky["strength"])


def vec(mathutils, v):
	"""The scene stays in glTF's axes here (+Y up), so vectors go in as they are."""
	return mathutils.Vector((float(v[0]), float(v[1]), float(v[2])))


def add_lamps(bpy, mathutils, sc, lights):
	for k, li in enumerate(lights):
		color = li["color"]
		if li["type"] == "directional":
			lamp = bpy.data.lights.new(f"light{k}", "SUN")
			lamp.energy = li["intensity"] / 683.0
			lamp.angle = 0.0
		else:
			lamp = bpy.data.lights.new(f"light{k}", "POINT" if li["type"] == "point" else "SPOT")
			lamp.energy = li["intensity"] * 4.0 * math.pi / 683.0
			lamp.shadow_soft_size = 0.0
			if li["type"] == "spot":
				lamp.spot_size = 2.0 * li["outer"]
				lamp.spot_blend = 1.0 - li["inner"] / li["outer"] if li["outer"] > 0 else 0.0
		lamp.color = tuple(float(c) for c in color)
		lamp.use_shadow = True
		ob = bpy.data.objects.new(f"light{k}", lamp)
		rot = vec(mathutils, li["direction"]).to_track_quat("-Z", "Y").to_matrix().to_4x4()
		ob.matrix_world = mathutils.Matrix.Translation(vec(mathutils, li["position"])) @ rot
		sc.collection.objects.link(ob)


def build(bpy, mathutils, scene, a):
	bpy.ops.wm.read_factory_settings(use_empty=True)
	sc = bpy.context.scene
	for mi_index, (v, f) in scene.by_material().items():
		m = scene.materials[mi_index]
		me = make_mesh(bpy, f"mesh{mi_index}", v, f)
		pbr = m if a.integrator == "principled" and not m["lambertian"] else None
		if m["pane"]:
			me.materials.append(make_pane(bpy, m["name"], m["base"] * m["transmission"], m["ior"]))
		else:
			me.materials.append(make_material(bpy, m["name"], m["base"], m["emission"], pbr))
		sc.collection.objects.link(bpy.data.objects.new(f"mesh{mi_index}", me))
	world = bpy.data.worlds.new("world")
	world.use_nodes = True
	bg = world.node_tree.nodes.get("Background") or world.node_tree.nodes.new("ShaderNodeBackground")
	env = scene.environment or [0.0, 0.0, 0.0]
	bg.inputs["Color"].default_value = (*[float(x) for x in env], 1.0)
	bg.inputs["Strength"].default_value = 1.0 if scene.environment else 0.0
	if scene.sky is not None:
		sky_world(bpy, world.node_tree, bg, scene.sky)
	sc.world = world
	add_lamps(bpy, mathutils, sc, scene.lights)
	portals = 0
	if scene.has_sky() and a.integrator != "noportal":
		for r in scene.portal_rects():
			li = bpy.data.lights.new(r["name"], "AREA")
			li.shape = "RECTANGLE"
			# The light emits along its -Z: -Z is the portal's normal, into the room.
			li.size, li.size_y = 2 * r["half"][1], 2 * r["half"][0]
			li.cycles.is_portal = True
			ob = bpy.data.objects.new(r["name"], li)
			ob.matrix_world = frame_matrix(mathutils, r["v"], r["u"], -r["normal"], r["center"])
			sc.collection.objects.link(ob)
			portals += 1
	c = scene.camera
	cam = bpy.data.cameras.new("camera")
	cam.sensor_fit = "VERTICAL"
	cam.angle_y = c["yfov"]
	cam.clip_start, cam.clip_end = 1e-3, 1e5
	ob = bpy.data.objects.new("camera", cam)
	right = np.cross(c["forward"], c["up"])
	right /= np.linalg.norm(right)
	up = np.cross(right, c["forward"])
	ob.matrix_world = frame_matrix(mathutils, right, up, -c["forward"], c["pos"])
	sc.collection.objects.link(ob)
	sc.camera = ob

	r = sc.render
	r.engine = "CYCLES"
	r.resolution_x, r.resolution_y, r.resolution_percentage = a.width, a.height, 100
	r.film_transparent = False
	r.threads_mode = "FIXED"
	r.threads = a.threads
	r.use_persistent_data = False
	r.image_settings.file_format = "OPEN_EXR"
	r.image_settings.color_depth = "32"
	r.image_settings.color_mode = "RGB"
	sc.view_settings.view_transform = "Raw"
	sc.view_settings.look = "None"
	sc.view_settings.exposure = 0.0
	sc.view_settings.gamma = 1.0
	cy = sc.cycles
	cy.device = "CPU"
	cy.use_adaptive_sampling = False
	cy.use_denoising = False
	cy.use_preview_denoising = False
	for vl in sc.view_layers:
		vl.cycles.use_denoising = False
	cy.sample_clamp_direct = 0.0
	cy.sample_clamp_indirect = 0.0
	cy.light_sampling_threshold = 0.0
	cy.blur_glossy = 0.0
	cy.caustics_reflective = True  # the defaults; off, they would drop light reflected by a pane
	cy.caustics_refractive = True
	bounces = max(0, a.depth - 2)
	cy.max_bounces = bounces
	cy.diffuse_bounces = bounces
	cy.glossy_bounces = bounces
	cy.transmission_bounces = bounces
	cy.volume_bounces = 0
	cy.transparent_max_bounces = bounces
	cy.min_light_bounces = 0
	cy.min_transparent_bounces = 0
	cy.pixel_filter_type = "BOX"
	cy.filter_width = 1.0
	cy.seed = a.seed
	cy.use_animated_seed = False
	if a.spp:
		cy.samples = a.spp
		cy.time_limit = 0.0
	else:
		cy.samples = 1 << 24
		cy.time_limit = a.seconds
	return portals


def render(scene, a, t0):
	import bpy
	import mathutils
	portals = build(bpy, mathutils, scene, a)
	stats = []
	bpy.app.handlers.render_stats.append(lambda s, *_: stats.append(s))
	with tempfile.TemporaryDirectory(prefix="peers-cy-") as tmp:
		path = os.path.join(tmp, "out.exr")
		bpy.context.scene.render.filepath = path
		setup = time.perf_counter() - t0
		start = time.perf_counter()
		bpy.ops.render.render(write_still=True)
		el = time.perf_counter() - start
		img = bpy.data.images.load(path)
		img.colorspace_settings.is_data = True
		w, h = img.size
		px = np.empty(w * h * img.channels, dtype=np.float32)
		img.pixels.foreach_get(px)
	rgb = px.reshape(h, w, img.channels)[::-1, :, :3]
	spp = 0
	for s in stats:
		m = re.search(r"Sample (\d+)/(\d+)", s)
		if m:
			spp = max(spp, int(m.group(1)))
	if a.spp:
		spp = a.spp
	return rgb, {"renderer": "cycles", "spp": spp, "render_seconds": round(el, 3), "setup_seconds": setup,
		     "variant": f"{portals} portal lights" if portals else "no portal"}
