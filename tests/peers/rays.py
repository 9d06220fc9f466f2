"""rays.py — Ajar's ray queries against Embree's, on one core
(`sh tests/peers/run.sh rays`; tests/peers/README.md).

A path sample's cost is mostly its ray queries (kernels/README.md, "Cost"), so this
compares the two tracers alone: closest-hit rays per second for 2^20
incoherent rays (origins uniform in the scene's bounds, directions uniform on
the sphere), one thread each, on the same core. Ajar's figure is
tests/bench/bench.c's `trace_closest` kernel (AJAR_BENCH_FILES); Embree's is
Mitsuba 3's `ray_intersect_preliminary` (its llvm_ad_rgb variant traces with
the Embree it bundles), on the same triangles and the same distribution of
rays. Runs alternate so the machine's drift reaches both; the best of each
is kept.

Environment: PEERS_SCENES (as driver.py: "window-room living-room
door-ajar"), PEERS_RUNS (3).
"""
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import backend_mitsuba  # noqa: E402
import driver  # noqa: E402
import scene as scene_mod  # noqa: E402

ROOT = driver.ROOT
BENCH_TARGET = "build/release/tests/bench"  # as the Makefile names it: make ignores other spellings
BENCH = os.path.join(ROOT, BENCH_TARGET)
NRAYS = 1 << 20


def ajar_mrays(path):
	"""trace_closest's rays per second, in millions, on one PoCL thread."""
	env = dict(os.environ, POCL_MAX_PTHREAD_COUNT="1", POCL_CPU_MAX_CU_NUM="1", AJAR_BENCH_FILES=path)
	out = subprocess.run([BENCH], cwd=ROOT, env=env, capture_output=True, text=True, check=True).stdout
	m = re.search(r"traversal\s+([0-9.]+) Mrays/s", out)
	if not m:
		raise RuntimeError(f"rays: no traversal figure in bench's output:\n{out}")
	return float(m.group(1))


class Embree:
	"""The scene's triangles in Mitsuba, with one batch of rays."""

	def __init__(self, mi, dr, sc, tmp):
		d = {"type": "scene"}
		verts = []
		for k, (v, f) in sc.by_material().items():
			p = os.path.join(tmp, f"mesh{k}.ply")
			backend_mitsuba.write_ply(p, v, f)
			d[f"mesh{k}"] = {"type": "ply", "filename": p, "face_normals": True}
			verts.append(v)
		self.dr = dr
		self.scene = mi.load_dict(d)
		allv = np.concatenate(verts)
		lo, hi = allv.min(axis=0), allv.max(axis=0)
		rng = np.random.default_rng(7)
		o = lo + (hi - lo) * rng.random((NRAYS, 3))
		z = 1.0 - 2.0 * rng.random(NRAYS)
		phi = 2.0 * np.pi * rng.random(NRAYS)
		s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
		dirs = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
		self.ray = mi.Ray3f(mi.Point3f(o.T.astype(np.float32)), mi.Vector3f(dirs.T.astype(np.float32)))
		self.run()  # the first query pays the JIT compilation

	def run(self):
		t0 = time.perf_counter()
		pi = self.scene.ray_intersect_preliminary(self.ray)
		self.dr.eval(pi.t)
		self.dr.sync_thread()
		return NRAYS / (time.perf_counter() - t0) * 1e-6


def main():
	if hasattr(os, "sched_setaffinity"):  # one core, shared by both
		os.sched_setaffinity(0, sorted(os.sched_getaffinity(0))[:1])
	if subprocess.run(["make", "-s", "all", BENCH_TARGET], cwd=ROOT).returncode != 0:
		sys.exit("rays: make failed")
	import mitsuba as mi
	import drjit as dr
	variant = backend_mitsuba.set_variant(mi)
	dr.set_thread_count(1)
	scenes = os.environ.get("PEERS_SCENES", "window-room living-room door-ajar").split()
	runs = int(os.environ.get("PEERS_RUNS", "3"))
	print(f"closest-hit rays per second, 2^20 incoherent rays, one core; Mitsuba {mi.__version__} {variant}")
	print(f"{'scene':<14} {'triangles':>9} {'Ajar':>12} {'Embree':>12} {'Embree / Ajar':>14}")
	for name in scenes:
		path = os.path.join("scenes", name, f"{name}.gltf")
		sc = scene_mod.Scene(os.path.join(ROOT, path))
		ntris = sum(len(f) for _, f in sc.by_material().values())
		with tempfile.TemporaryDirectory() as tmp:
			em = Embree(mi, dr, sc, tmp)
			a = e = 0.0
			for _ in range(runs):
				a = max(a, ajar_mrays(path))
				e = max(e, em.run())
		print(f"{name:<14} {ntris:>9} {a:>7.2f} Mrays {e:>7.2f} Mrays {e / a:>13.2f}x", flush=True)


if __name__ == "__main__":
	main()
