#!/bin/sh
# Installs the Debian packages Ajar needs when they are missing (as root), or
# prints the exact command to run. Used by `make demo`, `make test`, CI.
# OPTIONAL (Open MPI, for one render on several machines) is installed as
# root like the rest; without root its absence is only reported: `make`
# then builds Ajar with one rank and test_mpi is skipped.
PKGS="make gcc g++ pkg-config pocl-opencl-icd ocl-icd-opencl-dev opencl-headers \
libopenexr-dev libtinygltf-dev libstb-dev libcmocka-dev"
OPTIONAL="libopenmpi-dev openmpi-bin"
# make fuzz (FUZZ=1): clang with libFuzzer's runtime, and the JSON parser
# tinygltf's header includes (the harnesses compile tinygltf in).
[ "${FUZZ:-0}" = 1 ] && PKGS="$PKGS clang libclang-rt-14-dev nlohmann-json3-dev"
# make bench-portals (BENCH=1): Python writes the layouts it benches.
[ "${BENCH:-0}" = 1 ] && PKGS="$PKGS python3"
missing=""
optional=""
for p in $PKGS; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
for p in $OPTIONAL; do
	dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || optional="$optional $p"
done
[ -z "$missing$optional" ] && exit 0
if [ "$(id -u)" = 0 ]; then
	echo "Installing missing packages:$missing$optional"
	export DEBIAN_FRONTEND=noninteractive
	apt-get update -qq && apt-get install -y -qq --no-install-recommends $missing $optional >/dev/null || {
		echo "apt-get failed; run: apt-get install$missing$optional" >&2
		exit 1
	}
elif [ -n "$missing" ]; then
	echo "Missing packages:$missing$optional" >&2
	echo "Run: sudo apt-get install$missing$optional" >&2
	exit 1
else
	echo "Open MPI is not installed: Ajar is built for one machine and test_mpi is skipped" >&2
	echo "(for several machines: sudo apt-get install$optional)" >&2
fi
