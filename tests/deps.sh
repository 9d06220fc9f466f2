#!/bin/sh
# Installs the Debian packages Ajar needs when they are missing (as root), or
# prints the exact command to run. Used by `make demo`, `make test`, CI.
PKGS="make gcc g++ pkg-config pocl-opencl-icd ocl-icd-opencl-dev opencl-headers \
libopenexr-dev libtinygltf-dev libstb-dev libcmocka-dev libopenmpi-dev openmpi-bin"
missing=""
for p in $PKGS; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" = 0 ]; then
	echo "Installing missing packages:$missing"
	export DEBIAN_FRONTEND=noninteractive
	apt-get update -qq && apt-get install -y -qq --no-install-recommends $missing >/dev/null || {
		echo "apt-get failed; run: apt-get install$missing" >&2
		exit 1
	}
else
	echo "Missing packages:$missing" >&2
	echo "Run: sudo apt-get install$missing" >&2
	exit 1
fi
