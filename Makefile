# bijparam - GNU make
#
#   make / make all   build/bijparam (the CLI tool) and build/examples/<name>
#   make test         the developer's suite: check the dependencies
#                     (tests/ensure_deps.sh: prints what is missing and stops,
#                     never installs), build tests/test_*.c and tests/test_*.cpp
#                     into build/tests/ and run them and tests/test_*.sh with
#                     tests/run_all.sh: one line per program, a failing
#                     program's output in full, every output in build/logs/,
#                     last line "N passed, M failed"
#   make check        the long suite: the tests with a short form in make test
#                     in full (FULL_IN_CHECK below), the compile matrix
#                     (tests/test_compile.sh),
#                     every combination of the opt-out macros built as C
#                     and C++ (tests/test_build_matrix.sh),
#                     the tool cross-built for Windows (run under wine) and
#                     aarch64 (under qemu) writing the native bytes
#                     (tests/test_cross.sh),
#                     the fuzz harnesses (tests/test_fuzz.sh) and every test
#                     and the tool under ASan+UBSan and TSan
#                     (tests/test_sanitizers.sh: make asan, make tsan); logs
#                     in build/logs/check/, last line "N passed, M failed".
#   make deps         install what make test and make check need (apt-get,
#                     as root), saying what and why first
#   make demo         run the tool on its embedded mesh -> build/demo/demo.obj,
#                     demo.svg (UV layout), demo.png (checkerboard render)
#   make docs         regenerate the README pictures in docs/images/
#   make bench        bench/run.sh: timings on the meshes of tests/data,
#                     then bench/pack.sh (make bench-pack): packing utilization,
#                     then bench/scale.sh (make bench-scale), then
#                     bench/start.sh (make bench-start)
#   make bench-scale  bench/scale.sh: one chart subdivided to 8K, 133K, 298K
#                     and 1M faces (bench/subdivide.py), 1 and 2 threads: time,
#                     iterations, energy, bytes per face, exact checks
#   make bench-generated bench/generated.py: marching-cubes meshes of 150K,
#                     400K (genus 0, and one of genus 17 with 13 floating
#                     pieces), 1M and 4M faces made by bench/mcmesh.c into
#                     build/bench/generated/, each through --atlas 4096
#                     --padding 4 on 2 threads: stage times, wall and CPU,
#                     peak memory, charts, utilization, seam length, exact
#                     check (~15 min on a busy machine; not in bench)
#   make bench-start  bench/start.sh: the thin strips and lucy, --start auto
#                     against plain (~3 min; also in bench)
#   make bench-atlas  bench/atlas.sh: every mesh through --atlas 1024
#                     --padding 4, checked by uvcheck (~5 min; not in bench)
#   make bench-scaf   bench/scaf_ratio.py: time to SCAF's energy x 1.001 with
#                     the default direction, one thread, medians of 3 (~2 min;
#                     not in bench)
#   make bench-direction bench/direction.py: the default direction against
#                     Newton and the preconditioned L-BFGS on 15 charts of
#                     22K-357K faces, near and far from an isometry, one
#                     thread (~25 min of CPU; not in bench)
#   make bench-threads bench/threads.py: 1 against 2 threads on face, bimba
#                     and the 132K and 1M subdivided charts, idle then busy
#                     (~4 min; not in bench)
#   make bench-build  bench/build.sh: compile time (CPU and wall, median of 3)
#                     and bytes of text of the implementation per BP_NO_
#                     configuration, gcc and clang -O2 (~2 min; not in bench)
#   make bench-pool   bench/pool_bench.c: a batch of four meshes read,
#                     parameterized and written in one process, a pool per
#                     call against one kept bp_pool (~1 min; not in bench)
#   make python       the Python package's extension built in place
#                     (python/bijparam/_native*.so; python/README.md)
#   make bench-python bench/python_bench.py: the Python call against the
#                     tool on the bench meshes, wall and CPU, then two calls
#                     on two Python threads against one (~8 min; not in
#                     bench; docs/performance.md, "Python")
#   make clean        remove build/
#
# Every program includes bijparam.h, so every program depends on it.

# (make's built-in defaults are cc / g++: replace them, keep what the user sets)
ifeq ($(origin CC),default)
CC = gcc
endif
ifeq ($(origin CXX),default)
CXX = g++
endif
CFLAGS   ?= -std=c99 -O2 -Wall -Wextra -pedantic -Werror
CXXFLAGS ?= -std=c++11 -O2 -Wall -Wextra -pedantic -Werror
CPPFLAGS += -I. -Itests
LDLIBS   += -lm -pthread
# The C++ tests cross-check against OpenMesh (libopenmesh-dev).  At -O2, g++ 12
# inlines OpenMesh's PropertyT::push_back and reports a -Wmaybe-uninitialized
# inside OpenMesh's own code, so test files that include OpenMesh are compiled
# without that one warning; every other warning stays an error (the C builds
# still check bijparam.h for it).
OPENMESH_LIBS ?= -lOpenMeshCore
OPENMESH_CXXFLAGS ?= -Wno-maybe-uninitialized

BUILD := build
HEADERS := bijparam.h tests/bptest.h tests/bpt_triplets.h

TOOL     := $(BUILD)/bijparam
EXAMPLES := $(patsubst examples/%.c,$(BUILD)/examples/%,$(filter-out examples/bijparam.c,$(wildcard examples/*.c)))
C_TESTS   := $(patsubst tests/%.c,$(BUILD)/tests/%,$(wildcard tests/test_*.c))
CXX_TESTS := $(patsubst tests/%.cpp,$(BUILD)/tests/%,$(wildcard tests/test_*.cpp))
# The long scripts run in make check (the compile matrix, every combination
# of the opt-out macros, the Windows and aarch64 builds' bytes against the
# native ones, fuzzing, the sanitizer builds, the install and CMake
# consumers), the others in make test.
CHECK_SH  := tests/test_compile.sh tests/test_build_matrix.sh tests/test_cross.sh tests/test_fuzz.sh \
             tests/test_sanitizers.sh tests/test_install.sh tests/test_python_long.sh
SH_TESTS  := $(filter-out $(CHECK_SH),$(wildcard tests/test_*.sh))
ALL_TESTS := $(SH_TESTS) $(C_TESTS) $(CXX_TESTS)
# The programs of make test that take longest (about 5-15 s of CPU each).
LONG_FIRST := tests/test_python.sh $(addprefix $(BUILD)/tests/,test_visibility test_segment test_tutte) \
              tests/test_readme.sh tests/test_build_options.sh $(addprefix $(BUILD)/tests/,test_pins test_newton test_start test_sparse test_energy) \
              tests/test_tool_scale.sh tests/test_repair_tool.sh
# Tests with a short form under BP_TEST_QUICK (make test) and their full
# form in make check.
FULL_IN_CHECK := $(BUILD)/tests/test_threads $(BUILD)/tests/test_newton $(BUILD)/tests/test_start \
                 $(BUILD)/tests/test_segment $(BUILD)/tests/test_visibility $(BUILD)/tests/test_sparse \
                 $(BUILD)/tests/test_energy $(BUILD)/tests/test_tutte tests/test_readme.sh
# make test also builds the tool (shell tests drive it) once its source exists.
TEST_TOOL := $(if $(wildcard examples/bijparam.c),$(TOOL))

.PHONY: all test check tests deps deps-test deps-check demo docs bench bench-build bench-pack bench-scale bench-atlas bench-scaf bench-direction bench-start bench-threads bench-pool bench-cold bench-hot bench-generated python bench-python clean

all: $(TOOL) $(EXAMPLES)

# The tool uses the header's thread pool (BP_USE_PTHREADS); the library
# itself needs no link flags without it.
$(TOOL): examples/bijparam.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -DBP_USE_PTHREADS -pthread $< -o $@ $(LDLIBS)

$(BUILD)/examples/%: examples/%.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $< -o $@ $(LDLIBS)

# The C tests: -DBP_STATIC, so that what a test never calls is not
# compiled, and -Og instead of -O2: a third of the compile time, about -O1's
# run time.  The tool builds the whole header at CFLAGS; test_openmesh.cpp
# builds the whole header as C++ at -Og (a third of -O2's compile time; it
# runs in half a second): g++ -O2 of the whole header, warnings as errors,
# is tests/test_compile.sh's in make check.
TEST_CFLAGS ?= $(patsubst -O2,-Og,$(CFLAGS))
TEST_CXXFLAGS ?= $(patsubst -O2,-Og,$(CXXFLAGS))
# The tests that run in a fraction of a second are built at -O0: a third
# less compile time (1 s of CPU each) for at most 0.15 s more run time.
TEST_O0 := $(addprefix $(BUILD)/tests/,test_cancel test_gltf test_io test_limits test_repair test_view)
$(TEST_O0): TEST_CFLAGS = $(patsubst -O2,-O0,$(CFLAGS))
$(BUILD)/tests/%: tests/%.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -DBP_STATIC $(TEST_CFLAGS) $< -o $@ $(LDLIBS)

$(BUILD)/tests/%: tests/%.cpp $(HEADERS)
	@mkdir -p $(@D)
	$(CXX) $(CPPFLAGS) $(TEST_CXXFLAGS) $(if $(shell grep -l '<OpenMesh/' $<),$(OPENMESH_CXXFLAGS)) $< -o $@ $(OPENMESH_LIBS) $(LDLIBS)

# make deps installs (and says what and why); deps-test / deps-check only
# look, and stop with the missing packages and the command to install them.
deps:
	@bash tests/ensure_deps.sh install
deps-test:
	@bash tests/ensure_deps.sh check test
deps-check:
	@bash tests/ensure_deps.sh check check

# The Python extension (python/, built by make python below) is part of the
# tests once python/setup.py exists; defined before the tests rule uses it.
PYTHON ?= $(firstword $(wildcard /usr/bin/python3) python3)
PY_EXT := python/bijparam/_native$(shell $(PYTHON) -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))' 2>/dev/null)
TEST_PY := $(if $(wildcard python/setup.py),$(PY_EXT))

# The longest compiles first (the tool, the Python extension and
# test_openmesh.cpp build the whole header), so that make -j2 ends with two
# short ones instead of one long one.
tests: $(TEST_TOOL) $(TEST_PY) $(CXX_TESTS) $(C_TESTS)

# Dependencies first (the C++ tests need OpenMesh to compile), then build
# (its output in build/logs/build.log, shown only when it fails), then run,
# two programs at a time on two cores, the longest first so that both cores
# finish together.
test: deps-test
	@mkdir -p $(BUILD)/logs
	@echo "make test: building the tests (log: $(BUILD)/logs/build.log)"
	@$(MAKE) --no-print-directory -j2 tests > $(BUILD)/logs/build.log 2>&1 || { cat $(BUILD)/logs/build.log; echo "make test: the build failed"; echo "0 passed, 1 failed"; exit 1; }
	@BP_TEST_QUICK=1 bash tests/run_all.sh $(filter $(ALL_TESTS),$(LONG_FIRST)) $(filter-out $(LONG_FIRST),$(ALL_TESTS))

# The long suite: the compile matrix, fuzzing, the sanitizer builds (each a
# script printing BPTEST, so run_all.sh adds them up the same way) and the
# full forms of the tests make test runs short (BP_TEST_QUICK): test_threads
# (five meshes, 300 iterations, 1-8 threads, visibility; quick: bishop and
# spot), test_newton (lucy, beetle, camelhead 3 x 3, camelhead's allocator
# fallback), test_start (camelhead's progressive start), test_segment (the
# refine's and the split's allocation sweeps at every allocation, the
# 65,712-triangle sphere's twins), test_visibility (20000 rays against brute force, every
# view model on the cow), test_sparse (the 100 x 100 grid against the scalar
# factorization), test_energy (twice the coordinates of camel_b's chart
# against finite differences), test_tutte (the Krylov solve, the phases and
# BiCGSTAB on horse_cut too) and test_readme.sh (the example built six
# ways).
check: deps-check
	@mkdir -p $(BUILD)/logs/check
	@echo "make check: building the tests (log: $(BUILD)/logs/check/build.log)"
	@$(MAKE) --no-print-directory -j2 tests > $(BUILD)/logs/check/build.log 2>&1 || { cat $(BUILD)/logs/check/build.log; echo "make check: the build failed"; echo "0 passed, 1 failed"; exit 1; }
	@BP_TEST_LOGDIR=$(BUILD)/logs/check BP_TEST_TIMEOUT=1800 BP_TEST_JOBS=1 bash tests/run_all.sh $(FULL_IN_CHECK) $(CHECK_SH)

# test_pack_grid.c is test_pack.c compiled with a small packing grid.
$(BUILD)/tests/test_pack_grid: tests/test_pack.c

# The tool and the examples draw their pictures with examples/bp_draw.h.
$(TOOL) $(EXAMPLES): examples/bp_draw.h
$(TOOL) $(BUILD)/tests/test_gltf: examples/bp_gltf.h

# examples/thread_pool.c brings its own POSIX thread pool.
$(BUILD)/examples/thread_pool: examples/thread_pool.c $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) -pthread $< -o $@ $(LDLIBS)

# The built-in wavy cone (fig 3.3), parameterized: the mesh with its map
# (OBJ), the UV layout coloured by distortion (SVG) and the mesh with a
# checkerboard through the map (PNG).  Needs only the C compiler.
demo: $(TOOL)
	@mkdir -p $(BUILD)/demo
	$(TOOL) --demo -o $(BUILD)/demo/demo.obj --svg $(BUILD)/demo/demo.svg --png $(BUILD)/demo/demo.png
	@echo "demo output: $(BUILD)/demo/demo.obj (mesh with uv), $(BUILD)/demo/demo.svg (UV layout), $(BUILD)/demo/demo.png (checkerboard render)"

# The README pictures (docs/images/), each from one run of the tool: the
# camel's UV layout, the cow with a checkerboard with and without the
# barrier, spot's 13 charts by area ratio, the wavy cone (fig 3.3) with the
# barrier and without (its layout overlaps itself), and
# the optimization of spot's largest chart as a strip of frames (fig 3.8).
IMG := docs/images
docs: $(TOOL)
	@mkdir -p $(IMG) $(BUILD)/docs
	$(TOOL) tests/data/camel_b.obj --svg $(IMG)/camel_uv.svg --png $(IMG)/camel_checker.png --png-size 360 --checker 20
	$(TOOL) tests/data/cow_param_withSUV.obj --png $(IMG)/cow_checker.png --png-size 360 --png-views 2 --checker 20
	$(TOOL) tests/data/cow_param_withSUV.obj --no-barrier --png $(IMG)/cow_checker_nobarrier.png --png-size 360 --png-views 2 --checker 20
	$(TOOL) tests/data/spot.obj --svg $(IMG)/spot_area.svg --svg-color area --png $(IMG)/spot_checker.png --png-size 300 --png-views 3
	$(TOOL) tests/data/spot.obj --atlas 1024 --padding 4 --svg $(IMG)/spot_atlas.svg --svg-color area --png $(IMG)/spot_atlas_checker.png --png-size 300 --png-views 3 --checker 32
	$(TOOL) tests/data/fertility.off --atlas 1024 --padding 4 --svg $(IMG)/fertility_atlas.svg --svg-color chart --png $(IMG)/fertility_atlas_checker.png --png-size 300 --png-views 3 --checker 32
	sed -e '/^vt /d' -e '/^vn /d' -e 's|/[0-9/]*||g' tests/data/cow_param_withSUV.obj > $(BUILD)/docs/cow_novt.obj
	$(TOOL) $(BUILD)/docs/cow_novt.obj --atlas 1024 --padding 4 --svg $(IMG)/cow_atlas.svg --svg-color chart --png $(IMG)/cow_atlas_checker.png --png-size 300 --png-views 3 --checker 32
	$(TOOL) --demo --svg $(IMG)/cone_barrier.svg --png $(IMG)/cone_checker.png --png-size 360
	$(TOOL) --demo --no-barrier --svg $(IMG)/cone_nobarrier.svg
	rm -rf $(BUILD)/docs/frames
	$(TOOL) tests/data/spot.obj --frames $(BUILD)/docs/frames --frames-every 2
	cp $(BUILD)/docs/frames/strip.svg $(IMG)/spot_frames.svg
	@ls -l $(IMG)

bench: $(TOOL)
	bash bench/run.sh
	bash bench/pack.sh
	bash bench/scale.sh
	bash bench/start.sh

# reconstruction-like meshes at 150K-4M faces (bench/generated.py); the
# tool is copied first so that a rebuild during the run mixes no versions
$(BUILD)/bench/mcmesh: bench/mcmesh.c
	@mkdir -p $(@D)
	$(CC) -std=c99 -O2 -Wall -Wextra -pedantic -Werror $< -o $@ -lm
bench-generated: $(TOOL) $(BUILD)/bench/mcmesh
	cp $(TOOL) $(BUILD)/bench/bijparam-generated
	BENCH_TOOL=$(BUILD)/bench/bijparam-generated python3 bench/generated.py

# the start maps: thin strips and lucy, --start auto against plain
# (docs/performance.md, "Start maps")
bench-start: $(TOOL)
	bash bench/start.sh

# utilization of the outline packer and the time to pack 5,000 charts
# (docs/performance.md, "Packing")
bench-pack: $(TOOL)
	bash bench/pack.sh

# time and memory against the face count, up to a million faces (~2 min;
# docs/performance.md, "One chart from 8K to a million faces")
bench-scale: $(TOOL)
	bash bench/scale.sh

# every mesh through --atlas 1024 --padding 4: charts, seams, utilization,
# energy, time, exact check, padding (docs/performance.md, "Atlases")
bench-atlas: $(TOOL)
	bash bench/atlas.sh

# CPU seconds to SCAF's final energy x 1.001, one thread, medians of
# SCAF_RUNS (default 3) for each of SCAF_DIRECTIONS (default: the default
# direction; "precond newton" compares those two); docs/performance.md,
# "Against SCAF"
bench-scaf: $(TOOL)
	SCAF_DIRECTIONS="$(or $(SCAF_DIRECTIONS),default)" SCAF_RUNS="$(or $(SCAF_RUNS),3)" python3 bench/scaf_ratio.py

# the default direction against its two choices: each chart with
# --direction newton, precond and default (docs/performance.md, "The
# default direction")
bench-direction: $(TOOL)
	python3 bench/direction.py

# wall time with 1 and 2 threads on the charts above 50K faces, on the
# machine as it is, then with two spinning processes beside it
# (docs/performance.md, "Threads")
bench-threads: $(TOOL)
	python3 bench/threads.py 3 idle
	python3 bench/threads.py 3 busy face,bimba,n4_132K

# a batch in one process (read, parameterize, write four meshes of 8K-40K
# faces): a pool per call against one kept bp_pool (~1 min; docs/performance.md,
# "Many small charts, and batches")
POOL_MESHES = $(addprefix tests/data/,face_holes.off mech-holes-shark.off camelhead.off horse_cut.obj)
# compile time and text size of the implementation per build configuration
# (BP_NO_ macros), gcc and clang -O2: a table and build/bench/build.json
bench-build: bijparam.h bench/build.sh
	bash bench/build.sh

# which functions BP__COLD should mark: perf over every mesh of tests/data
# and the generated meshes (bench/cold.py; needs linux-perf, ~3 min)
bench-cold: bijparam.h bench/cold.py
	python3 bench/cold.py

# which functions BP__HOT should mark: perf over the README example built
# as the core library, on every mesh of tests/data (bench/hot.py; needs
# linux-perf, ~4 min)
bench-hot: bijparam.h bench/hot.py
	python3 bench/hot.py

bench-pool: bijparam.h bench/pool_bench.c
	mkdir -p $(BUILD)/bench/pool
	$(CC) -std=c99 -O2 -Wall -Wextra -pedantic -Werror -I. -DBP_USE_PTHREADS -pthread bench/pool_bench.c \
	    -o $(BUILD)/bench/pool_bench -lm
	$(BUILD)/bench/pool_bench $(BUILD)/bench/pool 7 $(POOL_MESHES)

clean:
	rm -rf $(BUILD) python/bijparam/_native*.so

# ---- the Python package (python/, python/README.md) -------------------------
#
# setuptools builds bijparam.h into the extension bijparam._native, in place
# (python/bijparam/), its objects in $(BUILD)/python.  PYTHON is Debian's
# interpreter, which has numpy (a python3 earlier on PATH may not).
python: $(PY_EXT)

$(PY_EXT): python/bijparam/_native.c python/setup.py bijparam.h examples/bp_gltf.h
	cd python && BIJPARAM_CFLAGS="-Wall -Wextra -Werror" $(PYTHON) setup.py -q build_ext --inplace --force \
	    --build-temp ../$(BUILD)/python/temp --build-lib ../$(BUILD)/python/lib

bench-python: $(TOOL) $(PY_EXT)
	PYTHONPATH=python $(PYTHON) bench/python_bench.py

# ---- reliability: fuzzing and sanitizers (docs/reliability.md) -------------
#
#   make fuzz    FUZZ_SECONDS=N (default 300): build the libFuzzer harnesses
#                of tests/fuzz/ with clang (installing libFuzzer if needed,
#                tests/fuzz/ensure_fuzzer.sh) and run all of them side by
#                side for N seconds; corpora grow in build/fuzz/corpus/,
#                crashes land in build/fuzz/artifacts/
#   make asan    every test (tests/test_*.c, *.cpp) and the tool under
#                AddressSanitizer + UndefinedBehaviorSanitizer in build/asan/,
#                run with tests/run_all.sh, then the tool on three meshes
#   make tsan    the tool with the header's thread pool and examples/
#                thread_pool.c under ThreadSanitizer in build/tsan/, run
#                with 2 threads on camel_b, spot and face_holes; then
#                tests/test_threads.c and tests/test_cancel.c (one cancel
#                flag read by charts solved in parallel), and
#                tests/test_sparse.c with the pool (the ordering and the
#                factorization on real pools of 2 and 3 threads), and
#                tests/test_io.c (the chunked reader and the writers on
#                pools of 2 and 3 threads)
.PHONY: fuzz asan tsan
FUZZ_SECONDS ?= 300
FUZZ_CC ?= clang
FUZZ_CFLAGS ?= -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
FUZZERS := $(BUILD)/fuzz/fuzz_obj $(BUILD)/fuzz/fuzz_off $(BUILD)/fuzz/fuzz_ply $(BUILD)/fuzz/fuzz_pipeline $(BUILD)/fuzz/fuzz_gltf
$(BUILD)/fuzz/fuzz_gltf: examples/bp_gltf.h

$(BUILD)/fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_common.h $(HEADERS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CPPFLAGS) -Itests/fuzz $(FUZZ_CFLAGS) $< -o $@ -lm

fuzz:
	FUZZ_CC=$(FUZZ_CC) bash tests/fuzz/ensure_fuzzer.sh
	$(MAKE) --no-print-directory -j2 $(FUZZERS)
	bash tests/fuzz/run_fuzzers.sh $(FUZZ_SECONDS) $(FUZZERS)

SAN_FLAGS ?= -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
SAN_ENV := ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
SAN_MESHES := tests/data/camel_b.obj tests/data/spot.obj tests/data/face_holes.off

# No -Werror here: the sanitizers change what gcc's flow analysis warns
# about; the normal build keeps every warning an error.
asan: deps-check
	$(MAKE) --no-print-directory -j2 BUILD=$(BUILD)/asan \
	    CFLAGS="-std=c99 -Wall -Wextra -pedantic $(SAN_FLAGS)" \
	    CXXFLAGS="-std=c++11 -Wall -Wextra -pedantic $(SAN_FLAGS)" tests
	@mkdir -p $(BUILD)/tests   # test_threads writes its scratch OBJ files there
	$(SAN_ENV) BP_TEST_LOGDIR=$(BUILD)/asan/logs bash tests/run_all.sh $(patsubst $(BUILD)/%,$(BUILD)/asan/%,$(C_TESTS) $(CXX_TESTS))
	@mkdir -p $(BUILD)/asan/out
	for m in $(SAN_MESHES); do \
	    $(SAN_ENV) $(BUILD)/asan/bijparam $$m --threads 2 --max-iters 200 -o $(BUILD)/asan/out/$$(basename $$m).obj || exit 1; \
	done
	$(SAN_ENV) $(BUILD)/asan/bijparam --demo -o $(BUILD)/asan/out/demo.obj
	$(SAN_ENV) $(BUILD)/asan/bijparam tests/data/gltf/BoxTextured.glb --threads 2 --atlas 256 -o $(BUILD)/asan/out/BoxTextured.glb
	$(SAN_ENV) $(BUILD)/asan/bijparam tests/data/gltf/MorphPrimitivesTest/MorphPrimitivesTest.gltf --threads 2 -o $(BUILD)/asan/out/MorphPrimitivesTest.gltf
	@echo "asan: the tests and the tool ran clean under ASan+UBSan"

TSAN_FLAGS ?= -O1 -g -fno-omit-frame-pointer -fsanitize=thread
TSAN_ENV := TSAN_OPTIONS=halt_on_error=1:exitcode=66
tsan:
	@mkdir -p $(BUILD)/tsan/out
	$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) -DBP_USE_PTHREADS -pthread \
	    examples/bijparam.c -o $(BUILD)/tsan/bijparam $(LDLIBS)
	$(if $(wildcard examples/thread_pool.c),$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) -pthread \
	    examples/thread_pool.c -o $(BUILD)/tsan/thread_pool $(LDLIBS))
	for m in $(SAN_MESHES); do \
	    $(TSAN_ENV) $(BUILD)/tsan/bijparam $$m --threads 2 --max-iters 100 -o $(BUILD)/tsan/out/$$(basename $$m).obj || exit 1; \
	done
	$(if $(wildcard examples/thread_pool.c),$(TSAN_ENV) $(BUILD)/tsan/thread_pool tests/data/spot.obj 2)
	$(TSAN_ENV) $(BUILD)/tsan/bijparam tests/data/gltf/BoxTextured.glb --threads 2 --atlas 256 -o $(BUILD)/tsan/out/BoxTextured.glb
	$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) tests/test_threads.c -o $(BUILD)/tsan/test_threads $(LDLIBS)
	@mkdir -p $(BUILD)/tests   # test_threads writes its scratch OBJ files there
	BP_TEST_QUICK=1 $(TSAN_ENV) $(BUILD)/tsan/test_threads > $(BUILD)/tsan/test_threads.log || { grep -v '^ok ' $(BUILD)/tsan/test_threads.log | tail -40; exit 1; }
	@tail -1 $(BUILD)/tsan/test_threads.log
	$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) tests/test_cancel.c -o $(BUILD)/tsan/test_cancel $(LDLIBS)
	$(TSAN_ENV) $(BUILD)/tsan/test_cancel > $(BUILD)/tsan/test_cancel.log || { grep -v '^ok ' $(BUILD)/tsan/test_cancel.log | tail -40; exit 1; }
	@tail -1 $(BUILD)/tsan/test_cancel.log
	$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) tests/test_io.c -o $(BUILD)/tsan/test_io $(LDLIBS)
	$(TSAN_ENV) $(BUILD)/tsan/test_io > $(BUILD)/tsan/test_io.log || { grep -v '^ok ' $(BUILD)/tsan/test_io.log | tail -40; exit 1; }
	@tail -1 $(BUILD)/tsan/test_io.log
	$(CC) $(CPPFLAGS) -std=c99 -Wall -Wextra -pedantic $(TSAN_FLAGS) -DBP_USE_PTHREADS -pthread tests/test_sparse.c \
	    -o $(BUILD)/tsan/test_sparse $(LDLIBS)
	$(TSAN_ENV) $(BUILD)/tsan/test_sparse > $(BUILD)/tsan/test_sparse.log || { grep -v '^ok ' $(BUILD)/tsan/test_sparse.log | tail -40; exit 1; }
	@tail -1 $(BUILD)/tsan/test_sparse.log
	@echo "tsan: no data race reported"

# ---- installation (header, tool, pkg-config file) --------------------------
#
#   make install   PREFIX=/usr/local (default) and DESTDIR= (staging root):
#                  $(PREFIX)/include/bijparam.h, $(PREFIX)/bin/bijparam and
#                  $(PREFIX)/share/pkgconfig/bijparam.pc, generated from
#                  bijparam.pc.in with the version of BP_VERSION_STRING in
#                  bijparam.h.  The .pc file goes to share/ because nothing
#                  in it depends on the architecture (header only, as
#                  Eigen's); pkg-config searches <prefix>/share/pkgconfig.
#                  BINDIR, INCLUDEDIR and PKGCONFIGDIR override the places.
#   make uninstall the same variables: removes exactly those three files.
#
# CMake installs the same files plus a CMake package (see CMakeLists.txt).
.PHONY: install uninstall
PREFIX ?= /usr/local
BINDIR ?= $(PREFIX)/bin
INCLUDEDIR ?= $(PREFIX)/include
PKGCONFIGDIR ?= $(PREFIX)/share/pkgconfig
INSTALL ?= install
BP_VERSION := $(shell sed -n 's/^\#define BP_VERSION_STRING "\([0-9][0-9.]*\)".*/\1/p' bijparam.h)

# Regenerated on every install: the file records PREFIX, which make cannot
# see change.  includedir is written relative to ${prefix} when it lies
# under it, so `pkg-config --define-prefix` can relocate the tree.
install: $(TOOL)
	@test -n "$(BP_VERSION)" || { echo "install: no BP_VERSION_STRING \"X.Y.Z\" in bijparam.h"; exit 1; }
	@mkdir -p $(BUILD)
	sed -e 's|@BP_PC_PREFIX@|$(PREFIX)|' \
	    -e 's|@BP_PC_INCLUDEDIR@|$(patsubst $(PREFIX)/%,$${prefix}/%,$(INCLUDEDIR))|' \
	    -e 's|@BP_PC_VERSION@|$(BP_VERSION)|' bijparam.pc.in > $(BUILD)/bijparam.pc
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(INCLUDEDIR) $(DESTDIR)$(PKGCONFIGDIR)
	$(INSTALL) -m 755 $(TOOL) $(DESTDIR)$(BINDIR)/bijparam
	$(INSTALL) -m 644 bijparam.h $(DESTDIR)$(INCLUDEDIR)/bijparam.h
	$(INSTALL) -m 644 $(BUILD)/bijparam.pc $(DESTDIR)$(PKGCONFIGDIR)/bijparam.pc

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/bijparam $(DESTDIR)$(INCLUDEDIR)/bijparam.h $(DESTDIR)$(PKGCONFIGDIR)/bijparam.pc
