"""images.py — EXR/PNG input and output and the error measure of the peer
benchmark.

EXR files are read and written with Mitsuba's Bitmap (its core needs no
variant), so no other EXR package is needed. rel_mse is tests/bench/bench.c's
formula exactly: the mean over pixels and the three channels of
(a - b)^2 / (b^2 + eps), eps = (0.1 mean(b))^2, mean(b) over pixels and
channels, so dark pixels are not judged by absolute error alone.
"""
import numpy as np


def read_exr(path):
	"""(H, W, 3) float64 linear RGB, and the header as a dict of strings."""
	import mitsuba as mi
	b = mi.Bitmap(path)
	a = np.array(b, dtype=np.float64)
	if a.ndim == 2:
		a = a[:, :, None]
	if a.shape[2] == 1:
		a = np.repeat(a, 3, axis=2)
	meta = {}
	props = b.metadata()
	for k in props.keys():
		meta[k] = str(props[k])
	return a[:, :, :3].copy(), meta


def write_exr(path, rgb):
	import mitsuba as mi
	mi.Bitmap(np.ascontiguousarray(rgb, dtype=np.float32), mi.Bitmap.PixelFormat.RGB).write(path)


def to_srgb8(rgb, exposure=0.0):
	c = np.clip(np.asarray(rgb) * 2.0 ** exposure, 0.0, 1.0)
	c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
	return (c * 255.0 + 0.5).astype(np.uint8)


def auto_exposure(rgb):
	"""Whole stops that bring the image mean to about 0.18."""
	m = float(np.mean(rgb))
	return 0.0 if m <= 0 else float(np.round(np.log2(0.18 / m)))


def write_png(path, rgb, exposure=0.0):
	from PIL import Image
	Image.fromarray(to_srgb8(rgb, exposure)).save(path)


def rel_mse(a, b, mean_b=None):
	"""tests/bench/bench.c's rel_mse (see the module comment)."""
	if mean_b is None:
		mean_b = float(np.mean(b))
	eps = 0.01 * mean_b * mean_b
	return float(np.mean((a - b) ** 2 / (b * b + eps)))


def reference_noise(r1, r2, mean):
	"""relMSE of R = (R1 + R2) / 2 against the truth, estimated as tests/bench/bench.c
	does: E|R1 - R2|^2 / 4 is the variance of R, over R^2 + eps."""
	r = 0.5 * (r1 + r2)
	return float(np.mean((r2 - r1) ** 2 / 4.0 / (r * r + 0.01 * mean * mean)))


def montage(path, images, labels, exposure, columns=5):
	"""Images in rows of `columns`, each with its label above, one PNG
	(what README shows as scenes/<scene>/peers.png)."""
	from PIL import Image, ImageDraw
	h, w = images[0].shape[:2]
	scale = max(1, 128 // max(w, h))
	tw, th, pad = w * scale, h * scale, 14
	cols = min(columns, len(images))
	rows = (len(images) + cols - 1) // cols
	out = Image.new("RGB", (cols * (tw + 4), rows * (th + pad)), (0, 0, 0))
	d = ImageDraw.Draw(out)
	for k, (im, lab) in enumerate(zip(images, labels)):
		tile = Image.fromarray(to_srgb8(im, exposure)).resize((tw, th), Image.NEAREST)
		x, y = (k % cols) * (tw + 4), (k // cols) * (th + pad)
		out.paste(tile, (x, y + pad))
		d.text((x + 2, y + 1), lab, fill=(255, 255, 255))
	out.save(path, optimize=True)
