#!/bin/sh
# tests/peers/run.sh — `make bench-peers`: Ajar against Blender Cycles, Mitsuba 3
# and LuxCoreRender at equal time on the portal scenes (see tests/peers/README.md).
# Optional and slow; never part of `make test`.
#
# Installs what it needs: Debian packages (as root, with apt-get; otherwise
# it prints the command), and bpy, mitsuba, pyluxcore, numpy and pillow from
# PyPI into a virtual environment in build/peers/venv (bpy pins numpy 1.26 and
# Python 3.11; the others accept that, so one environment serves all). Then
# runs tests/peers/driver.py. Knobs: PEERS_SECONDS, PEERS_SCENES, PEERS_SIZE,
# PEERS_REF_SECONDS, PEERS_DEPTH, PEERS_THREADS, PEERS_RENDERERS (driver.py).
# `run.sh rays` instead compares Ajar's ray queries with Embree's (rays.py);
# after driver.py, assets.py compares textured Khronos assets with Cycles
# through Blender's glTF importer (`run.sh assets`: only that). `run.sh pane`
# checks each renderer's thin glass pane against the analytic Fresnel (pane.py).
set -eu
cd "$(dirname "$0")/../.."

# libllvm19: Mitsuba's llvm_ad_rgb variant (Debian 12's LLVM 14/15 abort it);
# the X11/GL client libraries: bpy links them even when rendering headless.
DEBS="libllvm19 libgl1 libglx0 libglvnd0 libice6 libsm6 libx11-6 libxext6 libxfixes3 libxi6 libxkbcommon0 libxrender1 python3-venv"
missing=""
for p in $DEBS; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
	if [ "$(id -u)" = 0 ]; then
		apt-get update -qq
		DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing
	else
		echo "peers: missing Debian packages. Run: sudo apt-get install$missing" >&2
		exit 1
	fi
fi

PY=${PYTHON:-python3}
case "$($PY -c 'import sys; print("%d.%d" % sys.version_info[:2])')" in
3.11) ;;
*) echo "peers: bpy 5.0 needs Python 3.11; set PYTHON=python3.11" >&2; exit 1 ;;
esac
VENV=build/peers/venv
if [ ! -x "$VENV/bin/python" ]; then
	mkdir -p build/peers
	$PY -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c 'import bpy, mitsuba, pyluxcore, numpy, PIL' 2>/dev/null; then
	"$VENV/bin/pip" install -q --upgrade pip
	"$VENV/bin/pip" install -q bpy==5.0.1 mitsuba==3.9.1 pyluxcore==2.11.2 numpy==1.26.4 pillow
fi
if [ -e /usr/lib/x86_64-linux-gnu/libLLVM-19.so ]; then
	export DRJIT_LIBLLVM_PATH=${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM-19.so}
fi
# No __pycache__ in the source tree.
export PYTHONDONTWRITEBYTECODE=1
# `run.sh rays`: the ray queries alone against Embree's (rays.py).
if [ "${1:-}" = rays ]; then
	exec "$VENV/bin/python" tests/peers/rays.py
fi
# `run.sh pane`: each renderer's thin glass pane against the analytic Fresnel (pane.py).
if [ "${1:-}" = pane ]; then
	exec "$VENV/bin/python" tests/peers/pane.py
fi
# `run.sh assets`: only the textured Khronos assets against Blender's importer (assets.py).
if [ "${1:-}" = assets ]; then
	exec "$VENV/bin/python" tests/peers/assets.py
fi
"$VENV/bin/python" tests/peers/driver.py
exec "$VENV/bin/python" tests/peers/assets.py
