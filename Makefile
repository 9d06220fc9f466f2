# Ajar — build, test, bench, demo, install.
# `make help` lists the targets. Quiet unless V=1. Objects per mode in build/<mode>.

PREFIX ?= /usr/local
MODE ?= release
BUILD := build/$(MODE)
V ?= 0
Q := $(if $(filter 1,$(V)),,@)

CC ?= cc
CXX ?= c++
PKGS := OpenEXR OpenCL tinygltf stb
PKG_CFLAGS = $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS = $(shell pkg-config --libs OpenEXR OpenCL tinygltf stb 2>/dev/null)
WARN := -Wall -Wextra -Werror -Wno-unused-parameter
MODE_FLAGS_release := -O2 -g
MODE_FLAGS_debug := -O0 -g
MODE_FLAGS_asan := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
# make fuzz builds the library this way with clang (libFuzzer's coverage
# hooks, no main), into build/fuzz (tests/fuzz/README.md).
MODE_FLAGS_fuzz := -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
MFLAGS := $(MODE_FLAGS_$(MODE))
CPPFLAGS += -Iinclude -Isrc -Ikernels -MMD -MP
CFLAGS += -std=c11 -D_GNU_SOURCE -ffp-contract=off $(WARN) $(MFLAGS) -fPIC
CXXFLAGS += -std=c++14 $(WARN) $(MFLAGS) -fPIC
LDFLAGS += $(MFLAGS)
LDLIBS = $(PKG_LIBS) $(MPI_LIBS) -lz -lm -lpthread

# Open MPI (several machines, src/render/cluster.c): built in when found, unless
# MPI=0. Only cluster.c is compiled with its flags (and AJAR_MPI); without
# it the library is built exactly as before, with one rank.
# Found through pkg-config (ompi-c), else through Open MPI's compiler wrapper.
MPI_PC := $(shell pkg-config --exists ompi-c 2>/dev/null && echo y)
MPI_CC := $(if $(MPI_PC),,$(shell command -v mpicc 2>/dev/null))
MPI ?= $(if $(MPI_PC)$(MPI_CC),1,0)
ifeq ($(MPI),1)
MPI_CFLAGS := $(if $(MPI_PC),$(shell pkg-config --cflags ompi-c),$(shell mpicc --showme:compile)) -DAJAR_MPI
MPI_LIBS := $(if $(MPI_PC),$(shell pkg-config --libs ompi-c),$(shell mpicc --showme:link))
endif

# The library: every domain folder of src/ but the command (cli) and the
# build tools (tools).
LIB_DIRS := core scene image prepare device render
LIB_C := $(foreach d,$(LIB_DIRS),$(wildcard src/$(d)/*.c))
LIB_CXX := $(foreach d,$(LIB_DIRS),$(wildcard src/$(d)/*.cpp))
LIB_OBJS := $(LIB_C:src/%.c=$(BUILD)/src/%.o) $(LIB_CXX:src/%.cpp=$(BUILD)/src/%.o) $(BUILD)/kernel_source.o
CLI_OBJS := $(patsubst src/cli/%.c,$(BUILD)/cli/%.o,$(wildcard src/cli/*.c))
KERNELS := $(wildcard kernels/*.cl kernels/*/*.h)
# Tests in folders by what they need (tests/README.md): unit/ the host
# alone (no OpenCL device), render/ an OpenCL device, api/ the library, the
# program and Open MPI as a user meets them; bench/ is `make bench`, support/
# the helpers they share. Objects and binaries stay flat in $(BUILD)/tests.
UNIT_TESTS := $(notdir $(basename $(wildcard tests/unit/test_*.c))) test_lights_sky_planes_fine
TESTS := $(UNIT_TESTS) $(notdir $(basename $(wildcard tests/render/test_*.c tests/api/test_*.c)))

# One test binary per module, linking only what it tests (plus error.o).
obj = $(addprefix $(BUILD)/src/,$(addsuffix .o,$(1)))
# The BSDF's tests share tests/support/bsdf_check.c (materials, chi-square, albedo).
BSDF_DEPS := $(BUILD)/tests/bsdf_check.o $(call obj,core/error)
DEPS_test_bsdf := $(BSDF_DEPS)
DEPS_test_bsdf_bent := $(BSDF_DEPS)
DEPS_test_bsdf_layers := $(BSDF_DEPS)
DEPS_test_sampling := $(call obj,core/error)
DEPS_test_pane_planes := $(call obj,prepare/pane_planes)
# The glTF loader: the C++ file on tinygltf and its parts in C (src/scene/README.md).
GLTF_OBJS := scene/gltf scene/gltf_load scene/gltf_fail scene/gltf_values scene/gltf_accessors scene/gltf_textures \
	scene/gltf_materials scene/gltf_primitives scene/gltf_instances scene/gltf_nodes scene/gltf_cameras \
	scene/gltf_lights scene/gltf_environment scene/gltf_transform scene/gltf_decode scene/gltf_instancing \
	scene/gltf_confine scene/gltf_files scene/gltf_extensions
# The BVH build: its driver and threads, the node split, the wide collapse.
BVH_OBJS := prepare/bvh_build prepare/bvh_split prepare/bvh_collapse core/workers
DEPS_test_bvh := $(call obj,core/error core/input_file scene/scene scene/emit_mask scene/scene_share core/big_array $(BVH_OBJS) $(GLTF_OBJS) scene/tangents image/texture_file image/exr image/exr_read image/hdr)
# The light tests share tests/support/lit.c (the kernels' light code inside).
LIGHT_DEPS := $(BUILD)/tests/lit.o $(call obj,core/error core/input_file scene/scene scene/emit_mask scene/scene_share core/big_array prepare/light_tables image/exr image/exr_read image/hdr)
DEPS_test_lights_env := $(LIGHT_DEPS) $(call obj,prepare/portal_flux)
DEPS_test_lights_emitters := $(LIGHT_DEPS)
DEPS_test_lights_sample := $(LIGHT_DEPS)
DEPS_test_lights_sky_planes := $(LIGHT_DEPS) $(call obj,prepare/sky_tables prepare/portal_groups)
DEPS_test_lights_sky_planes_fine := $(patsubst %/lit.o,%/lit_fine.o,$(DEPS_test_lights_sky_planes))
# The scene module: the loader, the API's scene calls, the images a scene reads.
SCENE_DEPS := $(call obj,core/error core/input_file scene/scene scene/emit_mask scene/scene_share core/big_array scene/scene_api $(GLTF_OBJS) scene/tangents image/texture_file image/exr image/exr_read image/hdr)
DEPS_test_scene_shipped := $(BUILD)/tests/scene_files.o $(SCENE_DEPS)
DEPS_test_scene_api := $(BUILD)/tests/scene_files.o $(SCENE_DEPS)
DEPS_test_scene_gltf := $(BUILD)/tests/scene_files.o $(SCENE_DEPS)
DEPS_test_scene_materials := $(BUILD)/tests/scene_files.o $(SCENE_DEPS)
DEPS_test_scene_env := $(BUILD)/tests/scene_files.o $(SCENE_DEPS)
DEPS_test_exr := $(call obj,core/error core/input_file image/exr image/exr_read image/png)
DEPS_test_confine := $(SCENE_DEPS) $(call obj,image/png)
# The portal search: its driver and its steps (src/prepare/portal_find_parts.h).
PORTAL_FIND_OBJS := prepare/portal_find prepare/portal_find_rays prepare/portal_find_room prepare/portal_find_crossings \
	prepare/portal_find_planes prepare/portal_find_cells
# The kernels' integrators run on the host (tests/support/kernel_host.c) on
# scenes as prepare_scene makes them; the MIS tests add the oracle.
HOST_DEPS := $(BUILD)/tests/kernel_host.o $(call obj,core/error core/input_file scene/scene scene/emit_mask scene/scene_share core/big_array scene/scene_api $(GLTF_OBJS) scene/tangents image/texture_file image/exr image/exr_read image/hdr $(BVH_OBJS) prepare/light_tables prepare/prepare prepare/scene_bvh prepare/policy prepare/portal_flux prepare/sky_tables prepare/pane_planes prepare/portal_groups prepare/portal_slide $(PORTAL_FIND_OBJS) prepare/found_portals render/render_options)
DEPS_test_bdpt := $(BUILD)/tests/mis_oracle.o $(HOST_DEPS)
DEPS_test_punctual := $(HOST_DEPS)
DEPS_test_scene_share := $(HOST_DEPS)
DEPS_test_instances := $(BUILD)/tests/instance_scenes.o $(HOST_DEPS)
PORTAL_DEPS := $(BUILD)/tests/portal_scenes.o $(HOST_DEPS)
DEPS_test_portal_mis := $(BUILD)/tests/mis_oracle.o $(PORTAL_DEPS)
DEPS_test_portal_groups := $(PORTAL_DEPS)
DEPS_test_portal_sampling := $(PORTAL_DEPS)
DEPS_test_portal_policy := $(PORTAL_DEPS)
# The portal search on the host: scenes, the BVH, prepare_scene for the portals a render takes.
DEPS_test_portal_find := $(HOST_DEPS)
# Tests that render need the whole library.
DEPS_test_layout := $(BUILD)/libajar.a
DEPS_test_device_cdf := $(BUILD)/libajar.a
DEPS_test_render := $(BUILD)/libajar.a
DEPS_test_api := $(BUILD)/libajar.a
DEPS_test_cache := $(BUILD)/libajar.a
DEPS_test_cli := $(BUILD)/libajar.a
DEPS_test_multidevice := $(BUILD)/libajar.a
DEPS_test_integrators := $(BUILD)/tests/batch_means.o $(BUILD)/libajar.a
DEPS_test_traversal := $(BUILD)/libajar.a
DEPS_test_checkpoint := $(BUILD)/libajar.a
DEPS_test_aov := $(BUILD)/libajar.a
DEPS_test_subpaths := $(BUILD)/libajar.a
DEPS_test_mpi := $(BUILD)/libajar.a
DEPS_test_found_portals := $(BUILD)/tests/batch_means.o $(BUILD)/libajar.a
DEPS_test_cli_scene := $(BUILD)/libajar.a
DEPS_test_noise := $(BUILD)/libajar.a
DEPS_test_glass := $(BUILD)/tests/batch_means.o $(BUILD)/libajar.a
DEPS_test_limits := $(BUILD)/libajar.a
DEPS_test_instances_render := $(BUILD)/tests/instance_scenes.o $(BUILD)/libajar.a

.PHONY: FORCE all lib cli tests test test-unit asan fuzz fuzz-check fuzzers demo bench bench-portals bench-peers install uninstall clean deps help
all: lib cli

help:
	@echo "make demo       install missing packages, build, render scenes/cornell to out/demo.exr + .png"
	@echo "make test       install missing packages, build and run every test (cmocka)"
	@echo "make asan       host unit tests under AddressSanitizer + UBSan"
	@echo "make fuzz       libFuzzer harnesses (glTF, EXR, .hdr, textures, checkpoints), FUZZ_SECONDS each"
	@echo "make bench      BVH, traversal, samples/s, start-up figures"
	@echo "make bench-portals  found portals vs marked ones at equal time, every portal scene"
	@echo "make bench-peers  Cycles, Mitsuba 3, LuxCore vs Ajar at equal time (installs them; slow)"
	@echo "make install    PREFIX=$(PREFIX): ajar, libajar.{a,so}, ajar.h, ajar.pc"
	@echo "make all        library and CLI (MODE=release|debug|asan, V=1 for commands)"

deps:
	$(Q)sh tests/deps.sh

lib: $(BUILD)/libajar.a $(BUILD)/libajar.so
cli: build/ajar

build/ajar: $(BUILD)/ajar
	$(Q)cp $< $@

$(BUILD)/ajar: $(CLI_OBJS) $(BUILD)/libajar.a
	@echo "  LD      $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/libajar.a: $(LIB_OBJS)
	@echo "  AR      $@"
	$(Q)rm -f $@ && ar rcs $@ $^

$(BUILD)/libajar.so: $(LIB_OBJS) src/libajar.map
	@echo "  LD      $@"
	$(Q)$(CXX) -shared -Wl,-soname,libajar.so.0 -Wl,--version-script=src/libajar.map $(LDFLAGS) -o $@ $(LIB_OBJS) $(LDLIBS)

$(BUILD)/src/%.o: src/%.c
	@mkdir -p $(@D)
	@echo "  CC      $<"
	$(Q)$(CC) $(CPPFLAGS) $(PKG_CFLAGS) $(CFLAGS) -c -o $@ $<

# With or without MPI: mpi.flag changes when MPI does, and cluster.o is rebuilt.
$(BUILD)/src/render/cluster.o: src/render/cluster.c $(BUILD)/mpi.flag
	@mkdir -p $(@D)
	@echo "  CC      $< (MPI=$(MPI))"
	$(Q)$(CC) $(CPPFLAGS) $(MPI_CFLAGS) $(CFLAGS) -c -o $@ $<

$(BUILD)/mpi.flag: FORCE
	@mkdir -p $(@D)
	$(Q)echo '$(MPI) $(MPI_CFLAGS) $(MPI_LIBS)' | cmp -s - $@ || echo '$(MPI) $(MPI_CFLAGS) $(MPI_LIBS)' > $@

FORCE:

$(BUILD)/src/%.o: src/%.cpp
	@mkdir -p $(@D)
	@echo "  CXX     $<"
	$(Q)$(CXX) $(CPPFLAGS) $(PKG_CFLAGS) $(CXXFLAGS) -c -o $@ $<

$(BUILD)/cli/%.o: src/cli/%.c
	@mkdir -p $(@D)
	@echo "  CC      $<"
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

# Kernel sources are embedded in the library, flattened with #line markers
# so device compiler errors still name kernels/<file>:<line>.
$(BUILD)/embed_kernels: src/tools/embed_kernels.c
	@mkdir -p $(@D)
	$(Q)$(CC) -std=c11 $(WARN) -O1 -o $@ $<

$(BUILD)/kernel_source.c: $(KERNELS) $(BUILD)/embed_kernels
	@echo "  EMBED   kernels/ajar.cl"
	$(Q)$(BUILD)/embed_kernels kernels/ajar.cl > $@

$(BUILD)/kernel_source.o: $(BUILD)/kernel_source.c
	$(Q)$(CC) -std=c11 $(WARN) -O0 -c -o $@ $<

# The BSDF's albedo tables (energy compensation) are integrated from the
# kernels' own microfacet code by a build tool, one build for every MODE
# (always -O2, no sanitizers: the same bits), and kept in the tree so the
# kernels can include them; deterministic, so regenerating changes nothing.
TABLE_SRC := src/tools/bsdf_tables.c kernels/material/microfacet.h kernels/sample/sampling.h kernels/base/fastmath.h kernels/base/vec.h kernels/base/compat.h
build/tools/bsdf_tables: $(TABLE_SRC)
	@mkdir -p $(@D)
	$(Q)$(CC) -std=c11 -D_GNU_SOURCE -ffp-contract=off $(WARN) -Ikernels -O2 -o $@ $< -lm

kernels/material/bsdf_tables.h: build/tools/bsdf_tables
	@echo "  GEN     $@"
	$(Q)$< > $@.tmp && mv $@.tmp $@

define compile_test
@mkdir -p $(@D)
@echo "  CC      $<$(if $(TEST_CFLAGS), ($(TEST_CFLAGS)))"
$(Q)$(CC) $(CPPFLAGS) -Itests/support $(PKG_CFLAGS) $(CFLAGS) $(TEST_CFLAGS) -c -o $@ $<
endef
$(BUILD)/tests/%.o: tests/unit/%.c
	$(compile_test)
$(BUILD)/tests/%.o: tests/render/%.c
	$(compile_test)
$(BUILD)/tests/%.o: tests/api/%.c
	$(compile_test)
$(BUILD)/tests/%.o: tests/bench/%.c
	$(compile_test)
$(BUILD)/tests/%.o: tests/support/%.c
	$(compile_test)

# test_lights_sky_planes again with the planes' sky tables at 512 cells a
# side, as pt takes them under skies of 2048 columns or more
# (src/prepare/policy.c); lit.c holds the kernels' light code, so it too.
$(BUILD)/tests/test_lights_sky_planes_fine.o $(BUILD)/tests/lit_fine.o: TEST_CFLAGS := -DPORTAL_SKY_RES=512
$(BUILD)/tests/test_lights_sky_planes_fine.o: tests/unit/test_lights_sky_planes.c
	$(compile_test)
$(BUILD)/tests/lit_fine.o: tests/support/lit.c
	$(compile_test)

# Test binaries link their module objects (secondary expansion of DEPS_*).
.SECONDEXPANSION:
$(BUILD)/tests/test_%: $(BUILD)/tests/test_%.o $(BUILD)/tests/testutil.o $$(DEPS_test_$$*)
	@echo "  LD      $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS) -lcmocka

.SECONDARY:

# The ajar command with faults injected from its environment, for tests
# that run it in other processes (test_mpi).
$(BUILD)/tests/ajar_faults: $(BUILD)/tests/ajar_faults.o $(filter-out $(BUILD)/cli/main.o,$(CLI_OBJS)) $(BUILD)/libajar.a
	@echo "  LD      $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/tests/bench: $(BUILD)/tests/bench.o $(BUILD)/tests/testutil.o $(BUILD)/libajar.a
	@echo "  LD      $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS) -lcmocka

$(BUILD)/tests/bench_portals: $(BUILD)/tests/bench_portals.o $(BUILD)/libajar.a
	@echo "  LD      $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

tests: $(TESTS:%=$(BUILD)/tests/%) build/ajar $(BUILD)/tests/ajar_faults

test:
	$(Q)$(MAKE) --no-print-directory deps
	$(Q)$(MAKE) --no-print-directory tests
	$(Q)sh tests/run.sh $(BUILD) $(TESTS)

# Host tests that need no OpenCL device (tests/unit), under ASan + UBSan.
ASAN_TESTS := $(UNIT_TESTS)
asan:
	$(Q)$(MAKE) --no-print-directory deps
	$(Q)$(MAKE) --no-print-directory MODE=asan $(ASAN_TESTS:%=build/asan/tests/%)
	$(Q)ASAN_OPTIONS=detect_leaks=1 sh tests/run.sh build/asan $(ASAN_TESTS)

# Fuzzing (tests/fuzz/README.md): libFuzzer harnesses built with clang
# against the library's objects built the same way (MODE=fuzz, build/fuzz).
# make fuzz runs each for FUZZ_SECONDS; make fuzz-check is CI's bounded run.
FUZZ_TARGETS := gltf exr hdr texture checkpoint
FUZZ_SECONDS ?= 60
FUZZ_CFLAGS = -std=c11 -D_GNU_SOURCE $(WARN) $(MODE_FLAGS_fuzz) $(CPPFLAGS) -Itests/fuzz $(PKG_CFLAGS)
FUZZ_LINK = -fsanitize=fuzzer,address,undefined $(shell pkg-config --libs OpenEXR OpenCL 2>/dev/null) $(MPI_LIBS) -lz -lm -lpthread
FUZZ_SUPPORT := $(addprefix build/fuzz/fuzzers/,fuzz_common.o fuzz_stb.o fuzz_tinygltf.o)
FUZZERS := $(FUZZ_TARGETS:%=build/fuzz/fuzzers/fuzz_%)

build/fuzz/fuzzers/%.o: tests/fuzz/%.c
	@mkdir -p $(@D)
	@echo "  CC      $< (fuzz)"
	$(Q)clang $(FUZZ_CFLAGS) -c -o $@ $<

# Third-party code (tinygltf, stb) compiled in for its coverage: its own
# warnings are not ours. Nor are three kinds of UB in stb's arithmetic,
# which UBSan's pointer-overflow, nonnull-attribute and shift checks would
# report and which touch no memory: with a zero-length PNG IDAT it computes
# idata + 0 and memcpy(NULL, p, 0) before it has a buffer; a corrupt JPEG
# drives its bit count below 0 and a shift to 32 or more (garbage texels).
# AddressSanitizer still checks all of its memory.
build/fuzz/fuzzers/fuzz_stb.o: tests/fuzz/fuzz_stb.c
	@mkdir -p $(@D)
	@echo "  CC      $< (fuzz)"
	$(Q)clang -std=c11 -w $(MODE_FLAGS_fuzz) -fno-sanitize=pointer-overflow,nonnull-attribute,shift,signed-integer-overflow $(PKG_CFLAGS) -c -o $@ $<

build/fuzz/fuzzers/fuzz_tinygltf.o: tests/fuzz/fuzz_tinygltf.cpp
	@mkdir -p $(@D)
	@echo "  CXX     $< (fuzz)"
	$(Q)clang++ -std=c++14 -w $(MODE_FLAGS_fuzz) $(PKG_CFLAGS) -c -o $@ $<

build/fuzz/fuzzers/fuzz_%: build/fuzz/fuzzers/fuzz_%.o $(FUZZ_SUPPORT) build/fuzz/libajar.a
	@echo "  LD      $@"
	$(Q)clang++ -o $@ $^ $(FUZZ_LINK)

fuzzers:
	$(Q)$(MAKE) --no-print-directory MODE=fuzz CC=clang CXX=clang++ build/fuzz/libajar.a
	$(Q)$(MAKE) --no-print-directory $(FUZZERS)

fuzz:
	$(Q)FUZZ=1 sh tests/deps.sh
	$(Q)$(MAKE) --no-print-directory fuzzers
	$(Q)sh tests/fuzz/run.sh $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# CI: 20 s a harness, failing on any finding.
fuzz-check:
	$(Q)$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=20

demo:
	$(Q)$(MAKE) --no-print-directory deps
	$(Q)$(MAKE) --no-print-directory all
	@mkdir -p out
	build/ajar render scenes/cornell/cornell.gltf -o out/demo.exr --png out/demo.png --spp 64

# Optional: installs Blender Cycles, Mitsuba 3 and LuxCore from PyPI into
# build/peers/venv (tests/peers/README.md); never part of make test.
bench-peers:
	sh tests/peers/run.sh

bench:
	$(Q)$(MAKE) --no-print-directory deps
	$(Q)$(MAKE) --no-print-directory all $(BUILD)/tests/bench
	$(BUILD)/tests/bench

# Found portals against marked ones at equal time (tests/bench/bench_portals.c).
bench-portals:
	$(Q)$(MAKE) --no-print-directory deps BENCH=1
	$(Q)$(MAKE) --no-print-directory all $(BUILD)/tests/bench_portals
	$(BUILD)/tests/bench_portals
	python3 tests/bench/make_layouts.py $(BUILD)/layouts
	python3 scenes/door-ajar/make_door_ajar.py --angle 35 --name door-ajar-35 --out $(BUILD)/layouts
	$(BUILD)/tests/bench_portals scenes/door-ajar/door-ajar-20.gltf $(BUILD)/layouts/door-ajar-35.gltf \
		$(BUILD)/layouts/l-room.gltf $(BUILD)/layouts/terrace.gltf $(BUILD)/layouts/terrace-one-face.gltf \
		$(BUILD)/layouts/bay.gltf $(BUILD)/layouts/skylight.gltf

# The shared library is installed under its full version with the soname
# (libajar.so.0, as the link rule sets it) and the development name as links.
AJAR_VERSION = $(shell sed -n 's/.*AJAR_VERSION_STRING "\(.*\)"/\1/p' include/ajar.h)
INSTALL_LIB = $(DESTDIR)$(PREFIX)/lib

install: all
	@echo "  INSTALL $(DESTDIR)$(PREFIX)"
	$(Q)install -d $(DESTDIR)$(PREFIX)/bin $(INSTALL_LIB)/pkgconfig $(DESTDIR)$(PREFIX)/include
	$(Q)install -m 755 build/ajar $(DESTDIR)$(PREFIX)/bin/ajar
	$(Q)install -m 644 $(BUILD)/libajar.a $(INSTALL_LIB)/libajar.a
	$(Q)install -m 755 $(BUILD)/libajar.so $(INSTALL_LIB)/libajar.so.$(AJAR_VERSION)
	$(Q)ln -sf libajar.so.$(AJAR_VERSION) $(INSTALL_LIB)/libajar.so.0
	$(Q)ln -sf libajar.so.0 $(INSTALL_LIB)/libajar.so
	$(Q)install -m 644 include/ajar.h $(DESTDIR)$(PREFIX)/include/ajar.h
	$(Q)sed -e 's|@PREFIX@|$(PREFIX)|g' -e 's|@VERSION@|$(AJAR_VERSION)|g' \
		-e 's|@MPI@|$(if $(filter 1,$(MPI)),$(if $(MPI_PC), ompi-c,),)|g' src/ajar.pc.in \
		> $(INSTALL_LIB)/pkgconfig/ajar.pc

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/ajar $(INSTALL_LIB)/libajar.a $(INSTALL_LIB)/libajar.so $(INSTALL_LIB)/libajar.so.0 \
		$(INSTALL_LIB)/libajar.so.$(AJAR_VERSION) $(DESTDIR)$(PREFIX)/include/ajar.h $(INSTALL_LIB)/pkgconfig/ajar.pc

clean:
	rm -rf build out

# Where the test sources were before tests/ had folders, as older builds'
# dependency files still name them: nothing to make, so make rebuilds the
# objects from where the sources are now instead of stopping.
$(addprefix tests/,$(notdir $(wildcard tests/*/*.c))):

-include $(shell find build -name '*.d' 2>/dev/null)
