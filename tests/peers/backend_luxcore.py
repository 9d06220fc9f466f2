"""backend_luxcore.py — the scene in LuxCoreRender (pyluxcore), PATHCPU or
BIDIRCPU (--integrator path | bidir).

One mesh per material, `matte` (Lambertian) with the base colour; emitters
are matte with `emission` (radiance = colour x gain; LuxCore's triangle
lights emit from the front face only, like Ajar's). The environment is a
`constantinfinite` light; PATHCPU gets its visibility-map cache, LuxCore's
own way of finding the openings of an interior (it has no portals).

Matching: path.pathdepth.total = D (Ajar's and Mitsuba's max depth; LuxCore
counts segments the same way); Russian roulette is off (its roulette was
measured biased here: +6% BIDIRCPU, +10% PATHCPU on the window room), no
variance clamping, the 1-pixel box filter (width 0.5 is its radius), SOBOL
without adaptivity, the raw RGB film output (no image pipeline). BIDIRCPU
has no cap on the total path length: eye and light subpaths are each capped
at D (path.maxdepth, light.maxdepth), so it also renders some paths of more
than D segments; with D = 32 those carry < 0.01% of the light in these
scenes. Equal time: batch.halttime; samples per pixel are the engine's pass
count. The film comes out bottom-up (rows are flipped) and one row low (see build()).
"""
import time

import numpy as np


def props_from(pyluxcore, lines):
	p = pyluxcore.Properties()
	for k, v in lines.items():
		p.Set(pyluxcore.Property(k, v))
	return p


def vec(x):
	return [float(c) for c in x]


def build(pyluxcore, scene, a):
	if scene.sky is not None or scene.lights:
		raise ValueError(f"{scene.path}: sky images and punctual lights are not built for LuxCore here")
	sc = pyluxcore.Scene()
	props = {}
	for mi_index, (v, f) in scene.by_material().items():
		m = scene.materials[mi_index]
		sc.DefineMesh(f"mesh{mi_index}", [tuple(p) for p in np.asarray(v, dtype=np.float64).tolist()],
			      [tuple(t) for t in np.asarray(f, dtype=np.int64).tolist()], None, None, None, None)
		mat = f"scene.materials.mat{mi_index}"
		props[mat + ".type"] = "matte"
		props[mat + ".kd"] = vec(m["base"])
		if m["emission"].max() > 0:
			props[mat + ".emission"] = vec(m["emission"])
			props[mat + ".emission.gain"] = [1.0, 1.0, 1.0]
			props[mat + ".emission.power"] = 0.0
			props[mat + ".emission.efficency"] = 0.0
			props[mat + ".emission.normalizebycolor"] = False
		props[f"scene.objects.obj{mi_index}.shape"] = f"mesh{mi_index}"
		props[f"scene.objects.obj{mi_index}.material"] = f"mat{mi_index}"
	if scene.environment is not None:
		props["scene.lights.sky.type"] = "constantinfinite"
		props["scene.lights.sky.color"] = vec(scene.environment)
		props["scene.lights.sky.gain"] = [1.0, 1.0, 1.0]
		props["scene.lights.sky.visibilitymapcache.enable"] = a.integrator == "path"
	c = scene.camera
	fov = c["yfov"]
	if a.width < a.height:  # LuxCore's field of view spans the shorter side
		fov = 2 * np.arctan(np.tan(fov / 2) * a.width / a.height)
	props["scene.camera.type"] = "perspective"
	props["scene.camera.lookat.orig"] = vec(c["pos"])
	props["scene.camera.lookat.target"] = vec(c["pos"] + c["forward"])
	props["scene.camera.up"] = vec(c["up"])
	props["scene.camera.fieldofview"] = float(np.degrees(fov))
	# LuxCore's film lands one row lower than the other renderers' (measured
	# against Mitsuba: the relMSE between them is lowest with the whole image
	# moved up one row): its screen window is moved down one pixel, so that it
	# frames the same image.
	rx, ry = (a.width / a.height, 1.0) if a.width >= a.height else (1.0, a.height / a.width)
	dy = -2.0 * ry / a.height
	props["scene.camera.screenwindow"] = [-rx, rx, -ry + dy, ry + dy]
	sc.Parse(props_from(pyluxcore, props))
	return sc


def render(scene, a, t0):
	import pyluxcore
	pyluxcore.Init(lambda msg: None)
	sc = build(pyluxcore, scene, a)
	d = a.depth
	cfg = {
		"renderengine.type": "BIDIRCPU" if a.integrator == "bidir" else "PATHCPU",
		"native.threads.count": a.threads,
		"sampler.type": "SOBOL",
		"sampler.sobol.adaptive.strength": 0.0,
		"path.pathdepth.total": d, "path.pathdepth.diffuse": d, "path.pathdepth.glossy": d,
		"path.pathdepth.specular": d,
		"path.maxdepth": d, "light.maxdepth": d,
		"path.russianroulette.depth": 10 * d + 1,
		"light.russianroulette.depth": 10 * d + 1,
		"path.clamping.variance.maxvalue": 0.0,
		"path.forceblackbackground.enable": False,
		"film.width": a.width, "film.height": a.height,
		"film.filter.type": "BOX", "film.filter.width": 0.5,
		"film.imagepipelines.0.0.type": "NOP",
		"film.outputs.0.type": "RGB", "film.outputs.0.filename": "unused.exr",
		"batch.halttime": float(a.seconds) if a.seconds else 0.0,
		"batch.haltspp": int(a.spp) if a.spp else 0,
		"renderengine.seed": a.seed,
	}
	config = pyluxcore.RenderConfig(props_from(pyluxcore, cfg), sc)
	session = pyluxcore.RenderSession(config)
	setup = time.perf_counter() - t0
	start = time.perf_counter()
	session.Start()
	while True:
		time.sleep(0.05)
		session.UpdateStats()
		if session.HasDone():
			break
	session.Stop()
	stats = session.GetStats()
	spp = stats.Get("stats.renderengine.pass").GetInt()
	buf = np.zeros(a.width * a.height * 3, dtype=np.float32)
	session.GetFilm().GetOutputFloat(pyluxcore.FilmOutputType.RGB, buf)
	el = time.perf_counter() - start
	rgb = buf.reshape(a.height, a.width, 3)[::-1]
	return rgb, {"renderer": "luxcore", "spp": int(spp), "render_seconds": round(el, 3), "setup_seconds": setup,
		     "variant": cfg["renderengine.type"]}
