# ppbench build. `make` builds ./ppbench, `make test` runs the unit tests and the reduced
# study's regression gate, `make bench` reproduces the study into results/, `make perf` prints
# the benchmarks. Every entry point first runs scripts/deps.sh (installs Debian packages as
# root, otherwise says which command to run).
CC      ?= gcc
BUILD   ?= build
PKGS    := OpenCL lapacke openblas OpenEXR libpng inih libxxhash jansson liblzma
OPT     ?= -O2 -g
WARN    := -Wall -Wextra $(if $(WERROR),-Werror)
SAN     ?=
CFLAGS  += -std=c11 $(OPT) $(WARN) $(SAN) -fno-strict-aliasing
# Includes name their layer (#include "physics/maps.h", "kernels/ppb_conventions.h").
CPPFLAGS += -D_DEFAULT_SOURCE -D_POSIX_C_SOURCE=200809L -Isrc -I. \
            -Ikernels -DPPB_SOURCE_DIR='"$(CURDIR)"' -DPPB_SCRIPT_DIR='"$(CURDIR)/scripts"'
LDFLAGS += $(SAN)
# What ppbench runs started by make (test, bench, perf) log of their kernel builds goes under
# build/, not the user's cache (docs/reference.md: Outputs, "The kernel build log").
export PPBENCH_BUILD_LOG ?= $(CURDIR)/$(BUILD)/kernel-build.log

# src/<layer>/<module>.c, and src/methods/<slice>/<module>.c for each method; the layers and
# their order are in src/LAYERS, which scripts/check_layers.sh reads.
SRC   := $(filter-out src/drivers/main.c,$(wildcard src/*/*.c src/methods/*/*.c))
OBJ   := $(SRC:src/%.c=$(BUILD)/obj/%.o)
TESTS := $(patsubst tests/%.c,$(BUILD)/tests/%,$(wildcard tests/test_*.c))
LIB   := $(BUILD)/libppbench.a
BIN   ?= ppbench

.PHONY: all deps test test-long layers methods-check docs unit asan bench perf format format-check clean
all: $(BIN)

# Dependencies first: the pkg-config flags are only asked for once the packages are there.
$(BUILD)/deps.mk: scripts/deps.sh Makefile
	@mkdir -p $(BUILD)
	@bash scripts/deps.sh
	@echo "PKG_CFLAGS := $$(pkg-config --cflags $(PKGS) cmocka)" > $@.tmp
	@echo "PKG_LIBS := $$(pkg-config --libs $(PKGS)) -lm -lpthread" >> $@.tmp
	@echo "TEST_LIBS := $$(pkg-config --libs cmocka)" >> $@.tmp
	@mv $@.tmp $@
ifeq ($(filter clean format format-check,$(MAKECMDGOALS)),)
include $(BUILD)/deps.mk
endif
deps: $(BUILD)/deps.mk

$(BUILD)/obj/%.o: src/%.c | $(BUILD)/deps.mk
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(PKG_CFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

# The version provenance.txt records (drivers/experiment.c): `git describe --always` of HEAD,
# "-dirty" when tracked files differ from it, "unknown" outside git. git diff-index never
# writes the index (a build takes no git lock); a file merely touched may read as dirty.
# version.txt changes only with the version, so experiment.o and main.o (`ppbench --version`)
# are rebuilt then and only then.
PPB_VERSION := $(shell v=$$(git describe --always 2>/dev/null) && \
                 { git diff-index --quiet HEAD -- 2>/dev/null || v=$$v-dirty; } && echo $$v || \
                 echo unknown)
$(BUILD)/version.txt: FORCE
	@mkdir -p $(@D)
	@echo '$(PPB_VERSION)' | cmp -s - $@ || echo '$(PPB_VERSION)' > $@
$(BUILD)/obj/drivers/experiment.o $(BUILD)/obj/drivers/main.o: $(BUILD)/version.txt
$(BUILD)/obj/drivers/experiment.o $(BUILD)/obj/drivers/main.o: CPPFLAGS += -DPPB_VERSION='"$(PPB_VERSION)"'
FORCE:
# provenance.txt's ppbench.commit (the full hash of HEAD) and lib.inih (inih has no version
# call: the version built against, from pkg-config). Rebuilt with the version, as above.
PPB_COMMIT := $(shell git rev-parse HEAD 2>/dev/null || echo unknown)
$(BUILD)/obj/drivers/provenance.o: $(BUILD)/version.txt
$(BUILD)/obj/drivers/provenance.o: CPPFLAGS += -DPPB_COMMIT='"$(PPB_COMMIT)"' \
  -DPPB_INIH_VERSION='"$(shell pkg-config --modversion inih 2>/dev/null || echo unknown)"'

$(LIB): $(OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BIN): $(BUILD)/obj/drivers/main.o $(LIB)
	$(CC) $(LDFLAGS) -o $@ $^ $(PKG_LIBS)

# Burley's s refit to the searchlight study's Monte Carlo profiles (scripts/searchlight_study.sh).
$(BUILD)/burley_fit: scripts/burley_fit.c $(LIB) | $(BUILD)/deps.mk
	$(CC) $(CPPFLAGS) $(PKG_CFLAGS) $(CFLAGS) -o $@ $< $(LIB) $(LDFLAGS) $(PKG_LIBS)

# The slab solver's error budget against adding-doubling (docs/methods.md; scripts/slab_budget.c).
$(BUILD)/slab_budget: scripts/slab_budget.c $(LIB) | $(BUILD)/deps.mk
	$(CC) $(CPPFLAGS) $(PKG_CFLAGS) $(CFLAGS) -o $@ $< $(LIB) $(LDFLAGS) $(PKG_LIBS)

$(BUILD)/tests/%: tests/%.c $(LIB) tests/testutil.h tests/profileutil.h | $(BUILD)/deps.mk
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Itests $(PKG_CFLAGS) $(CFLAGS) -o $@ $< $(LIB) $(LDFLAGS) $(PKG_LIBS) \
	  $(TEST_LIBS)

# Unit tests: every tests/test_*.c is a cmocka suite; each prints cmocka's own summary.
# PPBENCH_CACHE set empty: no Monte Carlo reference cache (the user's default one included), so
# every suite traces what it runs: a changed Monte Carlo shows, whatever was cached before;
# the cache's own tests give their directories explicitly.
# What takes minutes is `make test-long`, which CI runs after `make test` (.ci/run), so that
# `make test` stays within 8 minutes on a 2-core machine: the physics validations against
# independent references (adding-doubling and the Monte Carlo at n > 1, rte2d against ppslab and
# the Monte Carlo, Chandrasekhar's H-function, the multipole's closed forms), the robustness
# grid with its thin, grazing, n = 2.5 corner, and the newcomer's path from a fresh clone.
LONG_TESTS := $(patsubst %,$(BUILD)/tests/%,test_fresnel test_deltam test_rte2d test_rte2d_beam \
                test_rte2d_ls test_burley test_dirpole test_multipole test_robust test_pbd)
UNIT_TESTS := $(filter-out $(LONG_TESTS),$(TESTS))
run-suites = @mkdir -p $(BUILD)/tmp; fail=0; for t in $(1); do \
	  echo "== $$t"; PPBENCH=$(CURDIR)/$(BIN) PPB_VERSION_FILE=$(CURDIR)/$(BUILD)/version.txt \
	    PPBENCH_CACHE= TMPDIR=$(CURDIR)/$(BUILD)/tmp $$t || fail=1; \
	done; exit $$fail
unit: $(BIN) $(UNIT_TESTS)
	$(call run-suites,$(UNIT_TESTS))
test-long: $(BIN) $(LONG_TESTS) test-newcomer test-rte2d-reference
	$(call run-suites,$(LONG_TESTS))

# rte2d against the shipped Monte Carlo references, chi-square per bin and totals in standard
# errors (tests/test_rte2d_reference.sh: the cheap version of scripts/rte2d_reference.sh).
.PHONY: test-rte2d-reference
test-rte2d-reference: $(BIN)
	@mkdir -p $(BUILD)/tmp
	@PPBENCH=$(CURDIR)/$(BIN) PPBENCH_CACHE= TMPDIR=$(CURDIR)/$(BUILD)/tmp \
	  bash tests/test_rte2d_reference.sh

# The layer check first: it reads includes only and fails in a second. Then the reference's
# check (docs/reference.md against what a few tiny runs write, a few seconds).
test: layers methods-check docs unit
	@bash tests/regress.sh

# The researcher's loop: shipped references, the committed study's guard, score's radiance
# check, partial external methods (tests/test_study_loop.sh, about 20 s); the newcomer's whole
# path from a fresh clone (tests/test_newcomer.sh: a clone, its build, every study case scored).
.PHONY: test-study-loop test-newcomer
test: test-study-loop
test-study-loop: $(BIN)
	@mkdir -p $(BUILD)/tmp
	@PPBENCH=$(CURDIR)/$(BIN) PPBENCH_CACHE= TMPDIR=$(CURDIR)/$(BUILD)/tmp bash tests/test_study_loop.sh
test-newcomer:
	@mkdir -p $(BUILD)/tmp
	@PPBENCH_CACHE= TMPDIR=$(CURDIR)/$(BUILD)/tmp timeout 900 bash tests/test_newcomer.sh

# scripts/chi2_radiance.awk (a method's bins against mc's, chi-square per bin) on hand-worked files.
.PHONY: test-chi2
test: test-chi2
test-chi2:
	@bash tests/test_chi2_radiance.sh

# The layer order is src/LAYERS; tests/test_layers.sh plants one violation of each rule.
layers:
	@bash scripts/check_layers.sh
	@bash tests/test_layers.sh

# No method is named outside its slice and the registry (docs/reference.md: Adding a method).
methods-check:
	@bash scripts/check_methods.sh
	@bash tests/test_check_methods.sh

docs: $(BIN)
	@mkdir -p $(BUILD)/tmp
	@PPBENCH=$(CURDIR)/$(BIN) PPBENCH_CACHE= TMPDIR=$(CURDIR)/$(BUILD)/tmp bash scripts/check_docs.sh

asan:
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	$(MAKE) BUILD=build-asan BIN=build-asan/ppbench OPT="-O1 -g" \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" \
	  unit test-long

bench: $(BIN)
	@bash scripts/bench.sh $(if $(QUICK),--quick)

# The shipped Monte Carlo references (references/<case>/) from the study `make bench` ran:
# its cached tallies, compressed (docs/reference.md, "The reference cache").
.PHONY: references
references:
	@bash scripts/references.sh

perf: $(BIN)
	@./ppbench perf

# Scale-out end to end, part of `make test`: GNU parallel, and a real one-node Slurm
# cluster the script starts and stops (as root; otherwise that part is skipped, and says so).
# 15 minutes at most, whatever happens.
.PHONY: test-cluster
test: test-cluster
test-cluster: $(BIN)
	@PPBENCH=$(CURDIR)/$(BIN) PPBENCH_CACHE= BUILD_DIR=$(CURDIR)/$(BUILD) timeout 900 bash tests/cluster.sh

FORMATTED = $(wildcard src/*/*.[ch] src/methods/*/*.[ch] src/methods/*/*.cl tests/*.[ch] \
              tests/kernels/*.cl kernels/*.h)
# Fuzzing (tests/fuzz/; CI runs it after the tests, .ci/run): the INI reader, the CSV reader
# and the external radiance validator,
# built with clang's libFuzzer, AddressSanitizer and UBSan, each run for FUZZ_SECONDS from its
# seed corpus (tests/fuzz/corpus/<target>, read only; what it finds goes to build-fuzz/).
FUZZ_CC      ?= clang
FUZZ_SECONDS ?= 20
FUZZ_TARGETS := config csv radiance
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_OBJ     := $(SRC:src/%.c=build-fuzz/obj/%.o)
.PHONY: fuzz
.SECONDARY: $(FUZZ_OBJ)
build-fuzz/obj/%.o: src/%.c | $(BUILD)/deps.mk
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CPPFLAGS) $(PKG_CFLAGS) -std=c11 -O1 -g -fsanitize=fuzzer-no-link $(FUZZ_SAN) \
	  -c $< -o $@
build-fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_util.h $(FUZZ_OBJ)
	$(FUZZ_CC) $(CPPFLAGS) $(PKG_CFLAGS) -std=c11 -O1 -g -fsanitize=fuzzer $(FUZZ_SAN) -o $@ \
	  $< $(FUZZ_OBJ) $(PKG_LIBS)
fuzz: $(FUZZ_TARGETS:%=build-fuzz/fuzz_%)
	@for t in $(FUZZ_TARGETS); do mkdir -p build-fuzz/found/$$t && \
	  echo "== fuzz $$t ($(FUZZ_SECONDS) s)" && TMPDIR=$(CURDIR)/build-fuzz \
	  build-fuzz/fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -max_len=65536 -timeout=10 \
	    -artifact_prefix=build-fuzz/found/$$t- build-fuzz/found/$$t tests/fuzz/corpus/$$t \
	    2>build-fuzz/$$t.log || { tail -40 build-fuzz/$$t.log; exit 1; }; done

format:
	clang-format -i $(FORMATTED)

format-check:
	clang-format --dry-run --Werror $(FORMATTED)

clean:
	rm -rf build build-asan build-fuzz ppbench

-include $(OBJ:.o=.d) $(BUILD)/obj/drivers/main.d
