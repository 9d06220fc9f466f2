"""energy.py — image means of Ajar and Cycles on interiors with glTF's own
materials (specular layers on), the check of Ajar's energy compensation
(kernels/material/bsdf.h) against Blender's Principled BSDF.

  build/peers/venv/bin/python tests/peers/energy.py

For each scene (ENERGY_SCENES, default "living-room bathroom"), two
variants written by scene.write_lambert_variant into build/peers/: `-pbr`
keeps every material's metallic, roughness, specular and ior (textures
become their mean colour, transmissive meshes are removed except smooth
thin panes, which both renderers build exactly: both see the same
materials), and `-lambert`, the control, makes every
material Lambertian. Ajar's `pt` and Cycles (Principled BSDF for the pbr
variant, Diffuse BSDF for the control) each render every variant with two
seeds at ENERGY_SPP (128) samples per pixel, ENERGY_SIZE (128) wide, depth
ENERGY_DEPTH (32), matched as for the equal-time benchmark (README.md).
Prints the image means, their noise (half the difference of the two
seeds) and Ajar / Cycles - 1; exits non-zero if a pbr variant's means
differ by more than ENERGY_TOL (2%) plus three times that noise.
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import driver  # noqa: E402
from scene import Scene, image_size, write_lambert_variant  # noqa: E402


def main():
	scenes = os.environ.get("ENERGY_SCENES", "living-room bathroom").split()
	spp = int(os.environ.get("ENERGY_SPP", "128"))
	size_spec = os.environ.get("ENERGY_SIZE", "128")
	depth = int(os.environ.get("ENERGY_DEPTH", "32"))
	tol = float(os.environ.get("ENERGY_TOL", "0.02"))
	os.makedirs(driver.OUT, exist_ok=True)
	driver.ensure_ajar()
	bad = 0
	for name in scenes:
		src = Scene(os.path.join(driver.ROOT, "scenes", name, name + ".gltf"))
		for kind in ("pbr", "lambert"):
			path = os.path.join(driver.OUT, f"{name}-energy-{kind}.gltf")
			for note in write_lambert_variant(src, path, pbr=kind == "pbr"):
				driver.log(f"{name}-{kind}: {note}")
			size = image_size(Scene(path), size_spec)
			means = {}
			for r in ("ajar-pt", "cycles-principled" if kind == "pbr" else "cycles"):
				m = []
				for seed in (1, 2):
					out = os.path.join(driver.OUT, f"{name}-energy-{kind}-{r}-{seed}")
					rgb, info = driver.render(r, path, size, depth, out, spp=spp, seed=seed)
					if rgb is None:
						raise SystemExit(f"energy: {r} failed on {path}")
					m.append(float(np.mean(rgb)))
					driver.log(f"{name}-{kind} {r} seed {seed}: mean {m[-1]:.5f} ({info.get('spp')} spp, "
						   f"{info.get('render_seconds')} s)")
				means[r] = (sum(m) / 2, abs(m[0] - m[1]) / 2)
			(ra, (ma, sa)), (rc, (mc, sc)) = means.items()
			ratio = ma / mc - 1
			noise = np.hypot(sa, sc) / mc
			driver.log(f"{name}-{kind}: ajar {ma:.5f} +- {sa:.5f}, cycles {mc:.5f} +- {sc:.5f}: "
				   f"ajar/cycles - 1 = {100 * ratio:+.2f}% (noise {100 * noise:.2f}%)")
			if kind == "pbr" and abs(ratio) > tol + 3 * noise:
				bad += 1
	return 1 if bad else 0


if __name__ == "__main__":
	sys.exit(main())
