# cdem-c build. Plain GNU Make + pkg-config. Every .c file in common/, solver/ and
# analysis/ (and their subfolders) is picked up automatically, so adding a module never
# edits this file.
#   make            build cdem-run and cdem-strain (build/)
#   make test       build and run every cmocka test (tests/test_*.c)
#   make asan       the same tests under address + undefined sanitizers (build-asan/)
#   make validate   longer physics validations (not part of make test)
#   make check-slurm   examples/slurm/sweep.sh under a single-node Slurm from Debian's
#                   packages (installed if missing; as root; make validate runs it too)
#   make bench      benchmarks (bench/)
#   make deps       install missing Debian packages (apt-get)
#   make demo       the main job: simulate the default model, analyse, render a picture
#   make fuzz       build the libFuzzer harnesses (tests/fuzz/, clang) and run each for
#                   FUZZ_SECONDS (default 600); FUZZ_HARNESSES picks a subset
#   make install    programs, man pages and bash completion into $(DESTDIR)$(PREFIX)
#                   (PREFIX default /usr/local); make uninstall removes them
#   make man, make completion, make measured, make errors   regenerate man/,
#                   completion/cdem-c.bash, docs/measured.md and docs/errors.md (tests fail
#                   when the committed ones are stale)
#   make times      time the README's commands on fresh clones into docs/times.md
#                   (EXAMPLES=1: make -C examples quick too)
# Every target builds with one job per core unless -jN is given (see MAKEFLAGS below).

# Parallel by default: one job per core (nproc), unless the command line says -jN (make -j1
# for a serial build; make 4.3 leaves -j1 out of MAKEFLAGS, and a command-line -j wins over
# this). A serial build of the ~100 sources and ~80 tests took 1.5 of `make demo`'s minutes
# on a fresh clone (issue 35). The tests themselves still run one at a time
# (tests/run_tests.sh); tests that run make (test_build, test_install) unset MAKEFLAGS.
# `make clean all` stays serial (clean would race the build).
ifeq ($(filter -j%,$(MAKEFLAGS))$(filter clean,$(MAKECMDGOALS)),)
MAKEFLAGS += -j$(shell nproc 2>/dev/null || echo 1)
endif

BUILD   ?= build
# An absolute BUILD inside the tree (the tests pass $CDEM_BUILD to make install) is the same
# folder as the relative one: one spelling, so that the dependency files (.d) name the
# targets as every other make of the tree does and a changed header rebuilds what includes it.
override BUILD := $(patsubst $(CURDIR)/%,%,$(BUILD))
CC      ?= gcc
PKGS    := hdf5 gsl cairo zlib
OPT     ?= -O2
# The project's flags live in CDEM_CFLAGS; a user's CFLAGS (and CPPFLAGS, LDFLAGS) come
# after them, so `make CFLAGS=-O1` changes the optimisation (the last -O wins) but never
# drops -std, -Werror, OpenMP or the include paths. OPT is what `make asan` and
# `make fuzz` swap.
CFLAGS  ?=
# -fno-math-errno: sqrt inlines without the errno branch (the results are the same IEEE values)
# -ffp-contract=off: no fused multiply-adds, whatever -march a user adds, so the scalar and
# the AVX2 force paths (and any two builds) round the same operations the same way
CDEM_CFLAGS := $(OPT) -g -fno-math-errno -ffp-contract=off
CDEM_CFLAGS += -std=c17 -Wall -Wextra -Werror -fopenmp -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE \
               -MMD -MP
# (after the layer's include paths: a library's header never shadows one of ours)
PKG_CFLAGS  := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
LDLIBS  += $(shell pkg-config --libs $(PKGS) 2>/dev/null) -lgif -lm -fopenmp
TEST_LDLIBS := $(shell pkg-config --libs cmocka 2>/dev/null)
VERSION := $(shell cat VERSION 2>/dev/null || echo 0.0.0)
CDEM_CFLAGS += -DCDEM_VERSION='"$(VERSION)"'

# Include paths per layer: they are the allowed dependencies. common sees only itself;
# the solver and the analysis each see common and themselves, never each other (the
# analysis needs nothing of the solver: it reads the solver's results through the file
# format in common/). Tests and fuzz harnesses see every layer. A file's layer is the first
# folder of its path. (A header in the same folder as its includer is found without -I,
# which is the same rule: a layer always sees itself.)
# The solver is layered by its second folder too (docs/solver.md, "Source files"), each
# seeing those before it: base/ (derived constants, checkpoint helpers), contact/ (the pair
# force), modes/ (the boundary modes: base/ only), step/ (the time step), packing/ (the
# assembly and the growth strata's deposits), run/ (the run loop) and main.c (all); between
# step/ and packing/ the physical processes: process/ (their interface and registry) and a
# folder per process (salt/), which sees process/ and the stepper.
# The analysis is layered again by its second folder (docs/analysis.md, "Source files"):
# measure/ sees only itself, input/ and export/ see measure/, draw/ sees only itself, and
# cli/ sees them all (each also sees common/).
INC_common   := -Icommon
INC_solver_base    := -Icommon -Isolver/base
INC_solver_contact := $(INC_solver_base) -Isolver/contact
INC_solver_modes   := $(INC_solver_base) -Isolver/modes
INC_solver_step    := $(INC_solver_contact) -Isolver/modes -Isolver/step
INC_solver_process := $(INC_solver_step) -Isolver/process
INC_solver_salt    := $(INC_solver_process) -Isolver/salt
INC_solver_packing := $(INC_solver_salt) -Isolver/packing
INC_solver_run     := $(INC_solver_packing) -Isolver/run
INC_solver   := $(INC_solver_run)
INC_analysis := -Icommon -Ianalysis
INC_analysis_measure := $(INC_analysis) -Ianalysis/measure
INC_analysis_input   := $(INC_analysis_measure) -Ianalysis/input
INC_analysis_export  := $(INC_analysis_measure) -Ianalysis/export
INC_analysis_draw    := $(INC_analysis) -Ianalysis/draw
INC_analysis_cli     := $(INC_analysis) -Ianalysis/measure -Ianalysis/input -Ianalysis/export \
                        -Ianalysis/draw -Ianalysis/cli
# the tests see every layer, the processes' own folders (solver/<id>/) included
INC_tests    := $(INC_solver) $(filter-out $(INC_solver),$(patsubst %/,-I%,$(wildcard solver/*/))) \
                $(filter-out -Icommon,$(INC_analysis_cli))
path_words = $(subst /, ,$(1))
# A solver folder without a line above is a process's (solver/process/process.h): it sees the
# processes' interface, the stepper below it and itself, so a new process adds no line here.
process_inc = $(if $(and $(filter solver,$(word 1,$(call path_words,$(1)))),$(word 3,$(call path_words,$(1)))),$(INC_solver_process) -Isolver/$(word 2,$(call path_words,$(1))))
layer_inc = $(or $(INC_$(word 1,$(call path_words,$(1)))_$(word 2,$(call path_words,$(1)))),$(call process_inc,$(1)),$(INC_$(word 1,$(call path_words,$(1)))))
compile_flags = $(CDEM_CFLAGS) $(1) $(PKG_CFLAGS) $(CPPFLAGS) $(CFLAGS)

COMMON_SRC   := $(wildcard common/*.c common/h5/*.c)
SOLVER_SRC   := $(filter-out solver/main.c,$(wildcard solver/*.c solver/*/*.c))
ANALYSIS_SRC := $(filter-out analysis/cli/main.c,$(wildcard analysis/*.c analysis/*/*.c))
TEST_SRC     := $(wildcard tests/test_*.c)

COMMON_OBJ   := $(COMMON_SRC:%.c=$(BUILD)/%.o)
SOLVER_OBJ   := $(SOLVER_SRC:%.c=$(BUILD)/%.o)
ANALYSIS_OBJ := $(ANALYSIS_SRC:%.c=$(BUILD)/%.o)
TEST_BIN     := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)

LIBCOMMON   := $(BUILD)/libcdem.a
LIBSOLVER   := $(BUILD)/libcdemsolver.a
LIBANALYSIS := $(BUILD)/libcdemanalysis.a
LIBS        := $(LIBANALYSIS) $(LIBSOLVER) $(LIBCOMMON)

.PHONY: all test asan validate bench deps demo clean format tests-build fuzz fuzz-build fuzz-bins
PROGRAMS := $(if $(wildcard solver/main.c),$(BUILD)/cdem-run) $(if $(wildcard analysis/cli/main.c),$(BUILD)/cdem-strain)
all: $(PROGRAMS)

deps:
	@sh scripts/deps.sh

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(call compile_flags,$(call layer_inc,$<)) -c $< -o $@

$(LIBCOMMON): $(COMMON_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBSOLVER): $(SOLVER_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^
$(LIBANALYSIS): $(ANALYSIS_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

# cdem-strain links no solver code: the analysis reads runs through common/'s file format
$(BUILD)/cdem-run: $(BUILD)/solver/main.o $(LIBSOLVER) $(LIBCOMMON)
	$(CC) $(call compile_flags,) $(LDFLAGS) -o $@ $^ $(LDLIBS)
$(BUILD)/cdem-strain: $(BUILD)/analysis/cli/main.o $(LIBANALYSIS) $(LIBCOMMON)
	$(CC) $(call compile_flags,) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/tests/%: tests/%.c $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(call compile_flags,$(INC_tests)) $(LDFLAGS) -o $@ $< $(LIBS) $(LDLIBS) $(TEST_LDLIBS)

tests-build: all $(TEST_BIN)

test: tests-build
	@sh tests/run_tests.sh $(BUILD)

asan:
	$(MAKE) BUILD=build-asan OPT="-O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined" test

validate: all $(BUILD)/tests/test_kill_survival $(BUILD)/tests/test_salt
	@sh tests/validate/run_validate.sh $(BUILD)

.PHONY: check-slurm
check-slurm: all
	@sh tests/validate/check_slurm.sh $(BUILD)

bench: all
	@sh bench/run_bench.sh $(BUILD)

demo: all
	@sh scripts/demo.sh $(BUILD)

# Fuzzing (tests/fuzz/README.md): every source compiled by clang with coverage
# instrumentation and address + undefined sanitizers into build-fuzz/, one libFuzzer binary
# per harness; tests/fuzz/run_fuzz.sh runs them one after another under nice.
FUZZ_SECONDS   ?= 600
FUZZ_HARNESSES ?= params fault_file cdem2d h5
FUZZ_OPT := -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined \
            -fno-sanitize-recover=undefined
fuzz: fuzz-build
	@sh tests/fuzz/run_fuzz.sh build-fuzz $(FUZZ_SECONDS) $(FUZZ_HARNESSES)
fuzz-build:
	$(MAKE) BUILD=build-fuzz CC=clang OPT="$(FUZZ_OPT)" fuzz-bins
fuzz-bins: $(FUZZ_HARNESSES:%=$(BUILD)/fuzz/fuzz_%)
$(BUILD)/fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_util.h $(LIBS)
	@mkdir -p $(dir $@)
	$(CC) $(call compile_flags,$(INC_tests)) $(LDFLAGS) -fsanitize=fuzzer -o $@ $< $(LIBS) $(LDLIBS)

format:
	clang-format -i common/*.[ch] common/h5/*.[ch] solver/*.[ch] solver/*/*.[ch] analysis/*/*.[ch] tests/*.[ch] 2>/dev/null || true

clean:
	rm -rf build build-asan build-fuzz

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)

# Man pages from the programs' --help text (tests/test_man.c fails when they are stale).
.PHONY: man
man: all
	/usr/bin/python3 scripts/help2roff.py $(BUILD) man

# docs/measured.md: the default model's counts and file sizes quoted by the docs, measured
# afresh (three default runs); make validate fails when the committed page is stale.
.PHONY: measured
measured: all
	/usr/bin/python3 scripts/measure_docs.py $(BUILD) > docs/measured.md.tmp
	mv docs/measured.md.tmp docs/measured.md

# docs/errors.md: every message of the sources (test_man fails when the page is stale,
# test_error_catalogue when a message of the sources is missing from it).
.PHONY: errors
errors:
	/usr/bin/python3 scripts/error_catalogue.py > docs/errors.md.tmp
	mv docs/errors.md.tmp docs/errors.md

# docs/times.md: the README's commands timed on fresh clones of HEAD (commit first);
# EXAMPLES=1 adds `make -C examples quick` (30 simulations). Run it under nice on a shared
# machine. test_times checks the docs' quoted times against the page.
.PHONY: times
times:
	sh scripts/time_fresh_clone.sh $(if $(filter 1,$(EXAMPLES)),--examples) > docs/times.md.tmp
	mv docs/times.md.tmp docs/times.md

# Bash completion from the programs' --help (tests/test_man.c fails when it is stale).
.PHONY: completion
completion: all
	/usr/bin/python3 scripts/help2completion.py $(BUILD) completion/cdem-c.bash

# make install / uninstall: the programs, their man pages and the bash completion under
# $(DESTDIR)$(PREFIX) (tests/test_install.c installs into a scratch DESTDIR and back out).
PREFIX      ?= /usr/local
BINDIR      := $(PREFIX)/bin
MANDIR      := $(PREFIX)/share/man/man1
BASHCOMPDIR := $(PREFIX)/share/bash-completion/completions
.PHONY: install uninstall
install: all
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(MANDIR) $(DESTDIR)$(BASHCOMPDIR)
	install -m 755 $(BUILD)/cdem-run $(BUILD)/cdem-strain $(DESTDIR)$(BINDIR)/
	install -m 644 man/cdem-run.1 man/cdem-strain.1 $(DESTDIR)$(MANDIR)/
	install -m 644 completion/cdem-c.bash $(DESTDIR)$(BASHCOMPDIR)/cdem-run
	install -m 644 completion/cdem-c.bash $(DESTDIR)$(BASHCOMPDIR)/cdem-strain
uninstall:
	rm -f $(DESTDIR)$(BINDIR)/cdem-run $(DESTDIR)$(BINDIR)/cdem-strain
	rm -f $(DESTDIR)$(MANDIR)/cdem-run.1 $(DESTDIR)$(MANDIR)/cdem-strain.1
	rm -f $(DESTDIR)$(BASHCOMPDIR)/cdem-run $(DESTDIR)$(BASHCOMPDIR)/cdem-strain
