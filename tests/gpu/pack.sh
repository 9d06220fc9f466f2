#!/bin/sh
# tests/gpu/pack.sh — run here (PoCL, the build machine) before a GPU session:
# builds Ajar and the tests, and fills build/gpu-carry (ignored by git) with
# what tests/gpu/run.sh needs on a GPU machine that has no compiler, no
# development packages and no PoCL:
#   bin/   ajar, the device tests, exr_compare, kernel_info
#   lib/   the shared libraries they use beyond libc, libm, libstdc++ (the
#          machine's own driver provides libnvidia-opencl)
#   ref/   PoCL's images of the check renders (run.sh renders the same scene,
#          seed and options on the GPU), and PoCL's speed on this machine:
#          speed.tsv, Msamples/s of one thread from its CPU time (user time),
#          times two for "two cores" (the machine is shared: wall-clock time
#          here is not the renderer's; kernels/README.md, "How the figures were measured")
# Then, with the device tool: command "bash tests/gpu/run.sh", carry
# ["build/gpu-carry"], timeout_s 590.
set -eu
C=build/gpu-carry
make -j2 all tests >/dev/null
rm -rf "$C"
mkdir -p "$C/bin" "$C/lib" "$C/ref"
cp build/ajar "$C/bin/"
for t in test_layout test_traversal test_subpaths test_render test_integrators; do
	cp "build/release/tests/$t" "$C/bin/"
done
${CC:-cc} -std=c11 -O2 -Wall -Wextra -Werror -Iinclude -o "$C/bin/exr_compare" tests/gpu/exr_compare.c \
	build/release/libajar.a $(pkg-config --libs OpenEXR OpenCL tinygltf stb) -lz -lstdc++ -lm -lpthread
${CC:-cc} -std=c11 -D_GNU_SOURCE -O2 -Wall -Wextra -Werror -Iinclude -Isrc -Ikernels -o "$C/bin/kernel_info" \
	tests/gpu/kernel_info.c build/release/libajar.a $(pkg-config --libs OpenEXR OpenCL tinygltf stb) -lz -lstdc++ -lm \
	-lpthread
for b in "$C"/bin/*; do ldd "$b"; done | awk '/=> \// {print $3}' | sort -u |
	grep -v -E '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt|ld-linux-x86-64)\.so' |
	while read -r lib; do cp -L "$lib" "$C/lib/"; done
export POCL_MAX_PTHREAD_COUNT=1
# The image checks: 128x128, 16 spp, seed 7 (run.sh uses the same).
for sc in living-room door-ajar; do
	for it in pt bdpt portal; do
		build/ajar render "scenes/$sc/$sc.gltf" -o "$C/ref/$sc-$it.exr" --size 128x128 --spp 16 --seed 7 \
			--integrator "$it" -q
	done
done
# PoCL's speed at the sizes of kernels/README.md's GPU table.
printf 'scene\tintegrator\tsize\tpocl_2core_msps\n' >"$C/ref/speed.tsv"
for job in "living-room 640x360 4" "door-ajar 512x512 2"; do
	set -- $job
	for it in pt bdpt portal; do
		build/ajar render "scenes/$1/$1.gltf" -o /tmp/gpu-pack-warm.exr --size "$2" --spp 1 --integrator "$it" -q
		u=$( { /usr/bin/time -f %U build/ajar render "scenes/$1/$1.gltf" -o /tmp/gpu-pack.exr --size "$2" \
			--spp "$3" --integrator "$it" -q; } 2>&1 | tail -1)
		w=${2%x*}
		h=${2#*x}
		awk -v n=$((w * h * $3)) -v u="$u" -v s="$1" -v i="$it" -v z="$2" \
			'BEGIN {printf "%s\t%s\t%s\t%.4f\n", s, i, z, 2 * n / u * 1e-6}' >>"$C/ref/speed.tsv"
	done
done
rm -f /tmp/gpu-pack.exr /tmp/gpu-pack-warm.exr
cat "$C/ref/speed.tsv"
du -sh "$C"
