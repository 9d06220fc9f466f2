"""driver.py — equal-time comparison of Ajar with Mitsuba 3, Blender Cycles
and LuxCoreRender on Ajar's portal scenes (`make bench-peers`, tests/peers/run.sh).

For each scene: a converged reference from two independent long halves
(cached in build/peers/refs/), then every renderer for the same wall time,
each in its own process; then the image mean against the reference's and
the relative MSE against it, with the reference's own noise subtracted
(relMSE(X, R) ~ relMSE_true(X) + relMSE(R)) and normalised to the nominal
time (relMSE x t_actual / T: variance falls as 1/time for unbiased
renderers). relMSE is tests/bench/bench.c's formula (images.rel_mse).

Environment: PEERS_SECONDS (20), PEERS_SCENES ("window-room living-room
door-ajar"; cornell also works, and "sky" names the sky- and lamp-lit scenes
window-room-sunset window-room-forest living-room-forest window-room-sun window-room-lamp
door-ajar-lamp atrium-forest window-room-fullsun, the last window-room-forest
with its sun as an unclipped download has it; "glazed" names window-room-glazed
window-room-forest-glazed living-room-forest-glazed, the rooms with a thin
glass pane in each window, scenes/skies/make_glazed.py), PEERS_SIZE (image width, height from the
camera's aspect ratio, or WxH; 128), PEERS_REF_SECONDS (each reference half;
300), PEERS_DEPTH (32), PEERS_THREADS (all cores), PEERS_RENDERERS (default
all: ajar-pt ajar-bdpt ajar-portal mitsuba mitsuba-ld cycles cycles-noportal
luxcore-path luxcore-bidir), PEERS_REF_<SCENE> (reference renderer for a
scene, e.g. PEERS_REF_DOOR_AJAR=mitsuba), PEERS_AJAR_MIS (Ajar's --mis; default
its own, auto).
"""
import hashlib
import json
import os
import resource
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)

import images  # noqa: E402
from scene import Scene, image_size, write_lambert_variant  # noqa: E402

OUT = os.path.join(ROOT, "build", "peers")
AJAR = os.path.join(ROOT, "build", "release", "ajar")
ALL = ["ajar-pt", "ajar-bdpt", "ajar-portal", "mitsuba", "mitsuba-ld", "cycles", "cycles-noportal", "luxcore-path",
       "luxcore-bidir"]
# Fastest to converge, measured on this machine (see the README of tests/peers).
DEFAULT_REF = {"window-room": "mitsuba", "living-room": "mitsuba", "door-ajar": "mitsuba", "cornell": "mitsuba",
	       "window-room-sunset": "mitsuba", "window-room-forest": "mitsuba", "living-room-forest": "mitsuba",
	       "window-room-sun": "mitsuba", "window-room-lamp": "mitsuba", "door-ajar-lamp": "mitsuba",
	       "atrium-forest": "mitsuba", "window-room-fullsun": "mitsuba",
	       # Mitsuba's shadow rays stop at a pane: on the glazed rooms its relMSE is 13-50x
	       # Ajar pt's at equal time (tests/peers/README.md, "Glazed windows").
	       "window-room-glazed": "ajar-pt", "window-room-forest-glazed": "ajar-pt",
	       "living-room-forest-glazed": "ajar-pt"}
# The scenes lit by sky images and KHR_lights_punctual lamps (scenes/skies/make_sky_scenes.py).
SKY_SCENES = ("window-room-sunset window-room-forest living-room-forest window-room-sun window-room-lamp door-ajar-lamp "
	      "atrium-forest window-room-fullsun")
# The rooms with one thin-walled pane 2 cm inside each window (scenes/skies/make_glazed.py).
GLAZED_SCENES = "window-room-glazed window-room-forest-glazed living-room-forest-glazed"
GROUPS = {"sky": SKY_SCENES, "glazed": GLAZED_SCENES}


# Sky scenes with the sun as a download with an unclipped sun has it. The
# shipped skies are Blender's 1k copies, whose suns are clipped (forest: peak
# 1,437, the sun 5% of the sky's power), so their rooms are lit mostly by the
# sky; here the sky's sun pixels (luminance above 0.3 of the peak) are
# multiplied, so the sun carries most of the light (forest x 60: 75%, peak
# 81,000; tests/peers/README.md, "An unclipped sun: window-room-fullsun").
# Made from the shipped scene into build/peers/ by sun_variant; not shipped.
SUN_VARIANTS = {"window-room-fullsun": ("window-room-forest", 60.0)}


def sun_variant(name):
	"""build/peers/NAME.gltf: SUN_VARIANTS[name]'s scene under its sky with
	the sun multiplied, and the note that says so."""
	base, gain = SUN_VARIANTS[name]
	src = os.path.join(ROOT, "scenes", base, base + ".gltf")
	doc = json.load(open(src))
	env = doc["scenes"][0]["extras"]["environment"]
	rgb, _ = images.read_exr(os.path.join(os.path.dirname(src), env["image"]))
	rgb = np.maximum(rgb, 0.0)
	lum = rgb @ np.array([0.2126, 0.7152, 0.0722])
	sun = lum > 0.3 * lum.max()
	rgb[sun] *= gain
	env["image"] = name + "-sky.exr"
	images.write_exr(os.path.join(OUT, env["image"]), rgb)
	for b in doc["buffers"]:
		dst = os.path.join(OUT, b["uri"])
		if not os.path.exists(dst):
			shutil.copyfile(os.path.join(os.path.dirname(src), b["uri"]), dst)
	out = os.path.join(OUT, name + ".gltf")
	with open(out, "w") as f:
		json.dump(doc, f)
	return out, f"{base} with its sky's {int(sun.sum())} sun pixels x {gain:g} (peak {lum.max() * gain:.0f})"


def supports(renderer, scene):
	"""Whether a renderer's backend builds this scene: LuxCore's here has
	only the uniform sky, mesh emitters and Lambertian surfaces (no panes)."""
	if renderer.startswith("luxcore"):
		return scene.sky is None and not scene.lights and not scene.has_panes()
	return True


def log(*a):
	print(*a, flush=True)


def env_threads():
	return int(os.environ.get("PEERS_THREADS", os.cpu_count() or 1))


def sub_env():
	e = dict(os.environ)
	llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
	if "DRJIT_LIBLLVM_PATH" not in e and os.path.exists(llvm):
		e["DRJIT_LIBLLVM_PATH"] = llvm
	if "PEERS_THREADS" in os.environ:
		# PoCL 3.x's CPU device (Debian 12) reads POCL_MAX_PTHREAD_COUNT and
		# ignores POCL_CPU_MAX_CU_NUM, which only PoCL 4 and later read.
		e["POCL_MAX_PTHREAD_COUNT"] = str(env_threads())
		e["POCL_CPU_MAX_CU_NUM"] = str(env_threads())
	return e


def pin_cpus():
	"""Runs in each renderer's child process before it starts: with
	PEERS_THREADS set, binds it to that many of this process's CPUs. The
	renderers' own thread settings are not enough: Cycles keeps two cores
	busy when bpy is told one thread."""
	if "PEERS_THREADS" in os.environ and hasattr(os, "sched_setaffinity"):
		cpus = sorted(os.sched_getaffinity(0))
		os.sched_setaffinity(0, cpus[:max(1, env_threads())])


def run_timed(cmd, **kw):
	"""subprocess.run, plus the cores the child kept busy on average: its
	CPU time (user + system) over the wall time. The table reports it, so a
	renderer that ignores PEERS_THREADS shows up instead of winning quietly."""
	before = resource.getrusage(resource.RUSAGE_CHILDREN)
	t = time.perf_counter()
	r = subprocess.run(cmd, preexec_fn=pin_cpus, **kw)
	wall = time.perf_counter() - t
	after = resource.getrusage(resource.RUSAGE_CHILDREN)
	cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
	return r, wall, cpu


def ensure_ajar():
	"""An up-to-date build/release/ajar: `make` (not -j: the machine is
	shared). The lead may be in the middle of an edit, so a failed build is
	retried a few times; if it keeps failing, an existing binary is used."""
	for attempt in range(4):
		if subprocess.run(["make", "-s", "all"], cwd=ROOT).returncode == 0 and os.path.exists(AJAR):
			return
		log(f"peers: make failed (attempt {attempt + 1}); retrying in 30 s")
		time.sleep(30)
	if not os.path.exists(AJAR):
		raise SystemExit("peers: build/release/ajar could not be built")
	log("peers: warning: make keeps failing; using the existing build/release/ajar")


def run_ajar(integrator, path, size, depth, out, seconds=0.0, spp=0, seed=7):
	w, h = size
	cmd = [AJAR, "render", path, "--integrator", integrator, "--size", f"{w}x{h}", "--max-depth", str(depth),
	       "--seed", str(seed), "-o", out, "-q"]
	if seconds:
		cmd += ["--time", str(seconds)]
	if spp:
		cmd += ["--spp", str(spp)]
	if os.environ.get("PEERS_AJAR_MIS"):
		cmd += ["--mis", os.environ["PEERS_AJAR_MIS"]]
	for attempt in range(4):
		r, wall, cpu = run_timed(cmd, cwd=ROOT, env=sub_env(), capture_output=True, text=True)
		if r.returncode == 0:
			break
		# Exit 3 (device: a kernel that does not build while the lead edits it) is retried.
		log(f"peers: ajar failed (exit {r.returncode}): {r.stderr.strip()[-400:]}")
		if r.returncode != 3:
			return None, None
		time.sleep(30)
	else:
		return None, None
	rgb, meta = images.read_exr(out)
	return rgb, {"spp": int(meta.get("ajar:spp", 0)), "render_seconds": float(meta.get("ajar:render_seconds", wall)),
		     "setup_seconds": round(wall - float(meta.get("ajar:render_seconds", wall)), 3), "cores": cpu / wall}


_sky_arrays = {}


def sky_array(path):
	"""For a scene with a sky image: the image as a .npy (float32, H x W x 3,
	clamped to >= 0 as Ajar reads it), made here once. Mitsuba's EXR reader
	never returns in a process bound to one CPU (PEERS_THREADS=1, pin_cpus),
	so its backend takes the pixels from this file instead."""
	if path not in _sky_arrays:
		env = json.load(open(path))["scenes"][0].get("extras", {}).get("environment", {})
		out = None
		if "image" in env:
			img = os.path.join(os.path.dirname(os.path.abspath(path)), env["image"])
			h = hashlib.sha1(open(img, "rb").read()).hexdigest()[:12]
			out = os.path.join(OUT, "skies", f"{os.path.splitext(os.path.basename(img))[0]}-{h}.npy")
			if not os.path.exists(out):
				os.makedirs(os.path.dirname(out), exist_ok=True)
				rgb, _ = images.read_exr(img)
				np.save(out, np.maximum(rgb, 0.0).astype(np.float32))
		_sky_arrays[path] = out
	return _sky_arrays[path]


def run_peer(renderer, path, size, depth, out_base, seconds=0.0, spp=0, seed=7):
	name, _, variant = renderer.partition("-")
	w, h = size
	npy = out_base + ".npy"
	cmd = [os.path.join(OUT, "venv", "bin", "python"), os.path.join(HERE, "backend.py"), name, path, npy,
	       "--size", f"{w}x{h}", "--depth", str(depth), "--seed", str(seed), "--threads", str(env_threads())]
	if sky_array(path):
		cmd += ["--sky-array", sky_array(path)]
	if variant:
		cmd += ["--integrator", variant]
	cmd += ["--seconds", str(seconds)] if seconds else ["--spp", str(spp)]
	env = sub_env()
	if name == "luxcore":
		libs = os.path.join(OUT, "venv", "lib", f"python{sys.version_info[0]}.{sys.version_info[1]}",
				    "site-packages", "pyluxcore.libs")
		pre = [os.path.join(libs, f) for f in sorted(os.listdir(libs)) if f.startswith("libtbbmalloc_proxy-")] \
			if os.path.isdir(libs) else []
		if pre:
			env["LD_PRELOAD"] = pre[0]
	limit = 600 + 4 * (seconds or 0)
	try:
		r, wall, cpu = run_timed(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=limit)
	except subprocess.TimeoutExpired:
		log(f"peers: {renderer} timed out after {limit:.0f} s")
		return None, None
	info = None
	for line in reversed(r.stdout.strip().splitlines()):
		if line.startswith("{"):
			info = json.loads(line)
			break
	if r.returncode != 0 or info is None or not os.path.exists(npy):
		log(f"peers: {renderer} failed (exit {r.returncode}): {(r.stderr or r.stdout).strip()[-800:]}")
		return None, None
	rgb = np.load(npy).astype(np.float64)
	images.write_exr(out_base + ".exr", rgb)
	os.remove(npy)
	info["cores"] = cpu / wall
	return rgb, info


def render(renderer, path, size, depth, out_base, seconds=0.0, spp=0, seed=7):
	if renderer.startswith("ajar-"):
		return run_ajar(renderer[5:], path, size, depth, out_base + ".exr", seconds, spp, seed)
	return run_peer(renderer, path, size, depth, out_base, seconds, spp, seed)


def file_hash(path):
	h = hashlib.sha1()
	g = json.load(open(path))
	h.update(json.dumps(g, sort_keys=True).encode())
	files = [b["uri"] for b in g.get("buffers", []) if "uri" in b and not b["uri"].startswith("data:")]
	env = g["scenes"][g.get("scene", 0)].get("extras", {}).get("environment", {})
	if "image" in env:
		files.append(env["image"])
	for uri in files:
		with open(os.path.join(os.path.dirname(path), uri), "rb") as f:
			h.update(f.read())
	return h.hexdigest()[:12]


def reference(name, path, size, depth, ref_seconds):
	"""Two independent halves by the scene's reference renderer, cached."""
	key = name.upper().replace("-", "_")
	rr = os.environ.get("PEERS_REF_" + key, DEFAULT_REF.get(name, "mitsuba"))
	w, h = size
	os.makedirs(os.path.join(OUT, "refs"), exist_ok=True)
	cache = os.path.join(OUT, "refs", f"{name}-{w}x{h}-d{depth}-{rr}-{ref_seconds:g}s-{file_hash(path)}.npz")
	if os.path.exists(cache):
		z = np.load(cache)
		log(f"  reference: {rr}, cached ({cache})")
		return z["r1"], z["r2"], {"renderer": rr, "spp": [int(x) for x in z["spp"]],
					  "seconds": [float(x) for x in z["seconds"]]}
	halves, spp, secs = [], [], []
	for k, seed in enumerate((1001, 1002)):
		log(f"  reference half {k + 1}/2: {rr}, {ref_seconds:g} s")
		img, info = render(rr, path, size, depth, os.path.join(OUT, f"{name}-ref{k + 1}"), seconds=ref_seconds,
				   seed=seed)
		if img is None:
			raise SystemExit(f"peers: reference for {name} failed")
		halves.append(img)
		spp.append(info["spp"])
		secs.append(info["render_seconds"])
	np.savez(cache, r1=halves[0], r2=halves[1], spp=spp, seconds=secs)
	return halves[0], halves[1], {"renderer": rr, "spp": spp, "seconds": secs}


def scene_path(name):
	"""The shipped scene, or its matched Lambertian variant when it is not
	Lambertian already (living-room). Thin panes count as Lambertian here:
	every renderer but LuxCore builds them exactly (scene.py)."""
	if name in SUN_VARIANTS:
		path, note = sun_variant(name)
		s = Scene(path)
		s.check_lambertian()
		return path, s, [note]
	folder = name[:-len("-glazed")] if name.endswith("-glazed") else name
	path = os.path.join(ROOT, "scenes", folder, name + ".gltf")
	s = Scene(path)
	try:
		s.check_lambertian()
		panes = sorted({s.materials[mi]["name"] for mi, _, _ in s.meshes if s.materials[mi]["pane"]})
		return path, s, [f"material {n}: smooth thin-walled pane, as shipped" for n in panes]
	except ValueError:
		pass
	var = os.path.join(OUT, name + "-lambert.gltf")
	notes = write_lambert_variant(s, var)
	v = Scene(var)
	v.check_lambertian()
	return var, v, notes


def bench_scene(name, seconds, size_spec, depth, ref_seconds, renderers, rows):
	path, s, notes = scene_path(name)
	size = image_size(s, size_spec)
	log(f"\n== {name}: {os.path.relpath(path, ROOT)}, {size[0]}x{size[1]}, max depth {depth}, {seconds:g} s each")
	for n in notes:
		log("  variant: " + n)
	r1, r2, rinfo = reference(name, path, size, depth, ref_seconds)
	ref = 0.5 * (r1 + r2)
	mean = float(ref.mean())
	noise = images.reference_noise(r1, r2, mean)
	log(f"  reference: {rinfo['renderer']} {rinfo['spp'][0]} + {rinfo['spp'][1]} spp, mean {mean:.5f}, "
	    f"its relMSE {noise:.2e}")
	exposure = images.auto_exposure(ref)
	images.write_png(os.path.join(OUT, f"{name}-reference.png"), ref, exposure)
	images.write_exr(os.path.join(OUT, f"{name}-reference.exr"), ref)
	for integ in ("pt", "bdpt", "portal"):  # PoCL compiles each kernel on its first run
		if "ajar-" + integ in renderers:
			run_ajar(integ, path, size, depth, os.path.join(OUT, "warmup.exr"), spp=1)
	tiles, labels, res = [ref], [f"reference ({rinfo['renderer']})"], {}
	for r in renderers:
		if r == "cycles-noportal" and not (s.portals and s.has_sky()):
			continue  # the same as "cycles" where no portal light is placed
		if not supports(r, s):
			log(f"  {r:16s} skipped: its backend has no sky images, punctual lights or panes")
			continue
		img, info = render(r, path, size, depth, os.path.join(OUT, f"{name}-{r}"), seconds=seconds)
		if img is None:
			rows.append({"scene": name, "renderer": r, "failed": True})
			continue
		t = info["render_seconds"]
		e = images.rel_mse(img, ref, mean) - noise
		e_t = e * t / seconds
		m = float(img.mean())
		# Standard error of the image mean, from the per-pixel errors (channels averaged).
		d = (img - ref).mean(axis=2)
		se = float(np.sqrt(np.mean(d * d) / d.size)) / mean
		dev = m / mean - 1
		ok = abs(dev) <= 4 * se + 0.003
		cores = info.get("cores", float("nan"))
		# A renderer busier than PEERS_THREADS allows had more of the machine than the others.
		fair = "PEERS_THREADS" not in os.environ or not cores > 1.15 * env_threads() + 0.1
		row = {"scene": name, "renderer": r, "spp": info["spp"], "seconds": t, "cores": cores, "fair": fair,
		       "setup": info.get("setup_seconds", 0.0), "mean": m, "dev": dev, "se": se, "ok": ok,
		       "relmse": e_t, "var_spp": e * info["spp"], "rate": info["spp"] / t if t > 0 else float("nan"),
		       "ref": rinfo["renderer"], "note": info.get("variant", "")}
		rows.append(row)
		res[r] = row
		log(f"  {r:16s} {info['spp']:7d} spp {t:6.1f} s {cores:4.2f} cores{'' if fair else ' (TOO MANY)'}  "
		    f"mean {m:.5f} ({100 * dev:+.2f}% +- {100 * se:.2f}%, {'ok' if ok else 'MISMATCH'})  "
		    f"relMSE at {seconds:g} s {e_t:.3e}")
		images.write_png(os.path.join(OUT, f"{name}-{r}.png"), img, exposure)
		tiles.append(img)
		labels.append(r)
	base = res.get("ajar-portal")
	for row in rows:
		if row["scene"] == name and not row.get("failed"):
			row["ratio"] = row["relmse"] / base["relmse"] if base and base["relmse"] > 0 else float("nan")
	images.montage(os.path.join(OUT, f"{name}-montage.png"), tiles, labels, exposure)
	log(f"  montage: {os.path.relpath(os.path.join(OUT, name + '-montage.png'), ROOT)} (exposure {exposure:+g} EV)")
	return rinfo


def table(rows, seconds, size_spec, depth, refs):
	out = [f"Equal time {seconds:g} s per render, image width {size_spec}, max depth {depth}, "
	       f"{env_threads()} thread{'' if env_threads() == 1 else 's'} each. relMSE is tests/bench/bench.c's (mean over pixels and channels of "
	       "(x - r)^2 / (r^2 + (0.1 mean r)^2)), minus the reference's own noise, times t/T. "
	       "ratio = relMSE / relMSE of ajar-portal (above 1: Ajar's portal integrator is better).", ""]
	for name, ri in refs.items():
		out.append(f"- {name}: reference by {ri['renderer']}, {ri['spp'][0]} + {ri['spp'][1]} spp in "
			   f"{ri['seconds'][0]:.0f} + {ri['seconds'][1]:.0f} s")
	out += ["", "cores = the renderer process's CPU time over its wall time (set-up included). "
		"relMSE x spp = variance per sample, spp/s = samples per pixel per second: relMSE at T is their "
		"ratio over T, so the two say whether a renderer wins per sample or per second.", "",
		"| scene | renderer | spp | render s | cores | mean vs reference | relMSE at T | relMSE x spp | spp/s "
		"| ratio vs ajar-portal |",
		"|---|---|---|---|---|---|---|---|---|---|"]
	for r in rows:
		if r.get("failed"):
			out.append(f"| {r['scene']} | {r['renderer']} | failed | | | | | | | |")
			continue
		check = f"{100 * r['dev']:+.2f}% ± {100 * r['se']:.2f}% {'ok' if r['ok'] else '**MISMATCH**'}"
		cores = f"{r['cores']:.2f}" + ("" if r["fair"] else " **too many**")
		out.append(f"| {r['scene']} | {r['renderer']} | {r['spp']} | {r['seconds']:.1f} | {cores} | {check} | "
			   f"{r['relmse']:.3e} | {r['var_spp']:.3g} | {r['rate']:.1f} | {r.get('ratio', float('nan')):.2f} |")
	return "\n".join(out) + "\n"


def main():
	seconds = float(os.environ.get("PEERS_SECONDS", "20"))
	scenes = [n for w in os.environ.get("PEERS_SCENES", "window-room living-room door-ajar").split()
		  for n in (GROUPS[w].split() if w in GROUPS else [w])]
	size_spec = os.environ.get("PEERS_SIZE", "128")
	ref_seconds = float(os.environ.get("PEERS_REF_SECONDS", "300"))
	depth = int(os.environ.get("PEERS_DEPTH", "32"))
	renderers = os.environ.get("PEERS_RENDERERS", " ".join(ALL)).split()
	os.makedirs(OUT, exist_ok=True)
	if any(r.startswith("ajar-") for r in renderers) or any(DEFAULT_REF.get(s, "").startswith("ajar") for s in scenes):
		ensure_ajar()
	rows, refs = [], {}
	for name in scenes:
		refs[name] = bench_scene(name, seconds, size_spec, depth, ref_seconds, renderers, rows)
	md = table(rows, seconds, size_spec, depth, refs)
	with open(os.path.join(OUT, "results.md"), "w") as f:
		f.write(md)
	log("\n" + md)
	log(f"peers: images, montages and results.md in {os.path.relpath(OUT, ROOT)}/")
	return 1 if any(r.get("failed") or not r.get("ok", True) or not r.get("fair", True) for r in rows) else 0


if __name__ == "__main__":
	sys.exit(main())
