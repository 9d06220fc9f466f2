"""means.py — image means of one scene by several renderers, with standard errors
from independent seeds: the check that renderers compute the same image before
their noise is compared (e.g. the glazed rooms, whose pane each peer builds its
own way).

  build/peers/venv/bin/python tests/peers/means.py

MEANS_SCENE (window-room-glazed; any name the driver knows), MEANS_RENDERERS
("ajar-pt mitsuba cycles"), MEANS_SEEDS (8 renders per renderer, seeds 101...),
MEANS_SECONDS (20 per render) or MEANS_SPP (instead of a time), MEANS_SIZE
(64), PEERS_DEPTH (32), PEERS_THREADS as the driver. The standard error of a
renderer's mean is the spread of its seeds' means over sqrt(seeds), so it
includes every correlation within an image. Prints each mean and its
difference from the first renderer's, in units of the two standard errors
combined; exits non-zero where one exceeds 4.
"""
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import driver  # noqa: E402
from scene import image_size  # noqa: E402


def main():
	name = os.environ.get("MEANS_SCENE", "window-room-glazed")
	renderers = os.environ.get("MEANS_RENDERERS", "ajar-pt mitsuba cycles").split()
	seeds = int(os.environ.get("MEANS_SEEDS", "8"))
	seconds = float(os.environ.get("MEANS_SECONDS", "20"))
	spp = int(os.environ.get("MEANS_SPP", "0"))
	depth = int(os.environ.get("PEERS_DEPTH", "32"))
	os.makedirs(driver.OUT, exist_ok=True)
	path, s, notes = driver.scene_path(name)
	size = image_size(s, os.environ.get("MEANS_SIZE", "64"))
	if any(r.startswith("ajar-") for r in renderers):
		driver.ensure_ajar()
	driver.log(f"{name}: {os.path.relpath(path, driver.ROOT)}, {size[0]}x{size[1]}, depth {depth}, {seeds} seeds x "
		   + (f"{spp} spp" if spp else f"{seconds:g} s"))
	res = {}
	for r in renderers:
		if r.startswith("ajar-"):  # PoCL compiles the kernel on its first run
			driver.run_ajar(r[5:], path, size, depth, os.path.join(driver.OUT, "warmup.exr"), spp=1)
		m, n = [], 0
		for k in range(seeds):
			img, info = driver.render(r, path, size, depth, os.path.join(driver.OUT, f"{name}-means-{r}-{k}"),
						  seconds=0.0 if spp else seconds, spp=spp, seed=101 + k)
			if img is None:
				raise SystemExit(f"means: {r} failed")
			m.append(img.reshape(-1, 3).mean(axis=0))
			n += info["spp"]
		m = np.array(m)
		grey = m.mean(axis=1)  # each seed's mean over pixels and channels
		mean, se = float(grey.mean()), float(grey.std(ddof=1)) / math.sqrt(seeds)
		res[r] = (mean, se)
		driver.log(f"  {r:12s} {n:8d} spp  mean {mean:.5f} +- {100 * se / mean:.2f}% "
			   f"(rgb {' '.join(f'{x:.5f}' for x in m.mean(axis=0))}; seeds {' '.join(f'{x:.5f}' for x in grey)})")
	first = renderers[0]
	bad = 0
	for r in renderers[1:]:
		a, sa = res[first]
		b, sb = res[r]
		z = (b - a) / math.hypot(sa, sb)
		bad += abs(z) > 4
		driver.log(f"  {r} / {first} - 1 = {100 * (b / a - 1):+.2f}% ({z:+.1f} standard errors)")
	return 1 if bad else 0


if __name__ == "__main__":
	sys.exit(main())
