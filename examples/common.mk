# Shared settings of the example Makefiles (included by examples/<x>/Makefile).
#
#   make              full (paper) size; results in out/
#   make QUICK=1      reduced sizes and runtimes (-s overrides from each folder's Q_* variables);
#                     results in out-quick/, so quick and paper results never mix
#   make quick        the same as make QUICK=1; make paper the same as make (as in the
#                     folders that do not include this file: wedge, salt-*)
#   make -j2          independent simulations run in parallel
#   NICE=10           niceness of cdem-run (the machines are shared; NICE=0 to disable)
#
# The programs are taken from the repository's build/ (built once if missing). They are
# order-only prerequisites: rebuilding cdem-run does not re-run finished simulations;
# `make clean` in the folder (or deleting an .h5) does. A simulation re-runs when its
# parameter file changes; every analysis and picture re-runs when its .h5 changes.

.DEFAULT_GOAL := all

EXAMPLES_DIR := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
ROOT         := $(abspath $(EXAMPLES_DIR)/..)
BUILD        ?= $(ROOT)/build
CDEM_RUN     := $(BUILD)/cdem-run
CDEM_STRAIN  := $(BUILD)/cdem-strain
NICE         ?= 10
# Idle OpenMP threads sleep instead of spinning (5x faster on a loaded machine,
# docs/performance.md); results do not depend on it.
OMP_WAIT_POLICY ?= passive
export OMP_WAIT_POLICY
PYTHON       ?= /usr/bin/python3

# EXAMPLES_OUT=DIR puts this folder's results in DIR/<folder> instead (make validate uses a
# scratch directory, so it always runs the current programs and leaves out*/ alone).
QUICK ?=
ifneq ($(EXAMPLES_OUT),)
OUT := $(EXAMPLES_OUT)/$(notdir $(CURDIR))
else ifeq ($(QUICK),1)
OUT := out-quick
else
OUT := out
endif

# $(call quick,ARGS): ARGS only when QUICK=1 (the -s overrides of a reduced run).
quick = $(if $(filter 1,$(QUICK)),$(1))

# cdem-run quietly at low priority. The output is written in place (renaming it would
# break the .xmf sidecar that names it); .DELETE_ON_ERROR and make's own clean-up on
# interrupt remove a partial .h5, so it is never taken as finished (these figure pipelines
# re-run a failed simulation rather than continue it with --resume; docs/guide.md's sweep
# keeps it instead). --force: make re-runs a target that is out of date, and cdem-run
# replaces an existing file only when told so.
# $(call simulate,MODEL.ini,OUT.h5,EXTRA -s ARGS)
simulate = nice -n $(NICE) $(CDEM_RUN) -q --force $(1) $(3) -o $(2)

# Renderings: 1000 px wide PNGs.
RENDER = $(CDEM_STRAIN) render --width 1000

$(CDEM_RUN) $(CDEM_STRAIN):
	$(MAKE) -C $(ROOT) BUILD=$(BUILD) $@

$(OUT):
	mkdir -p $@

TOOLS := $(CDEM_RUN) $(CDEM_STRAIN) $(OUT)

.PHONY: all clean clean-quick summary quick paper

# `make quick` = `make QUICK=1`, `make paper` = `make` (issue 46, item 13a: every folder has
# both; tests/test_examples_tools.c checks that `make -n quick` goes to out-quick/)
quick:
	+$(MAKE) QUICK=1 all
paper: all
.DELETE_ON_ERROR:
.SECONDARY:

clean:
	rm -rf out out-quick

MONTAGE = $(PYTHON) $(EXAMPLES_DIR)/montage.py

# The standard pipeline of one simulation NAME (from NAME.ini), used by the folders:
#   $(OUT)/NAME.h5         the run (extra -s overrides: $(Q_NAME) when QUICK=1, $(S_NAME) always)
#   $(OUT)/NAME-layers.png last increment, layer colours (extra render options: $(R_NAME))
#   $(OUT)/NAME-shear.png  last increment, total maximum shear strain
#   $(OUT)/NAME-info.txt   summary, stop reason and increments (cdem-strain info)
$(OUT)/%.h5: %.ini | $(TOOLS)
	$(call simulate,$<,$@,$(S_$*) $(call quick,$(Q_$*)))
$(OUT)/%-layers.png: $(OUT)/%.h5
	$(RENDER) $< --increment last $(R_$*) -o $@
$(OUT)/%-shear.png: $(OUT)/%.h5
	$(RENDER) $< --increment last --color total-max-shear $(R_$*) -o $@
$(OUT)/%-info.txt: $(OUT)/%.h5
	$(CDEM_STRAIN) info $< > $@
#   $(OUT)/NAME-measures.md  what cdem-strain measures in the last increment (measure.py:
#                            counts, surface, voids, fault zones; extra options $(M_NAME))
$(OUT)/%-measures.md: $(OUT)/%.h5 $(EXAMPLES_DIR)/measure.py
	$(PYTHON) $(EXAMPLES_DIR)/measure.py $(CDEM_STRAIN) $< $(M_$*) > $@

# $(OUT)/measures.md: the measures of every run the folder lists in MEASURED, in that order.
# (second expansion: the folder sets MEASURED after including this file)
.PHONY: measures
measures: $(OUT)/measures.md
.SECONDEXPANSION:
$(OUT)/measures.md: $$(foreach r,$$(MEASURED),$(OUT)/$$(r)-measures.md)
	{ echo "# Measures ($(if $(filter 1,$(QUICK)),quick,paper) size)"; echo; \
	  cat $^; } > $@
