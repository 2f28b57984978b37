# Two commands on a fresh Debian machine:
#   make test        build and run the test suite (what CI runs)
#   make examples    install the package to a temporary prefix, build examples/
#                    out of tree against it and run them (CI runs it too)
#   make reproduce   regenerate the figure runs, the short studies, the summary
#                    and every figure; check that the large tables are current
#   make sweep       regenerate the large tables (long runs, many states, timings)
# Each first installs any missing Debian package (target deps).

DEB_PACKAGES := cmake ninja-build g++ make libeigen3-dev libceres-dev libsundials-dev \
                nlohmann-json3-dev libcli11-dev libgtest-dev libbenchmark-dev libboost-dev \
                gnuplot-nox jq git libopenmpi-dev openmpi-bin clang libclang-rt-14-dev \
                python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
BUILD ?= build
NHI := $(BUILD)/bin/nhi
JOBS ?= 2
# The figures' shared look, and each method's line style as the methods declare
# it (nhi list --gnuplot), rewritten only when it changes.
STYLE := plots/style.gp plots/method_styles.gp

.PHONY: all deps build install test test-sanitize examples fuzz reproduce figures readme-tables sweep sweep-results check-sweep \
        sweep-scaling clean
all: build

# $(call APT,packages): apt-get install those of the packages not installed yet.
define APT
	@missing=""; for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "deps: installing$$missing"; \
	  if [ "$$(id -u)" -eq 0 ]; then SUDO=""; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -q && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing; \
	fi
endef

deps:
	$(call APT,$(DEB_PACKAGES))


# One build tree ($(BUILD)) and one compiler (CXX, clang++ by default: it
# compiles this code's templates in less than half of g++'s time) for
# everything: the library, the runner, the studies, the benchmark, the tests,
# the Python module ($(BUILD)/python) and the examples' install.
# NATIVE=ON builds for this CPU (faster, but results are then this CPU's own;
# see CMakeLists.txt).
NATIVE ?= OFF
CXX := clang++
# Debian's Python, whose packages (pybind11, NumPy, pytest, matplotlib) make deps installs.
PYTHON ?= /usr/bin/python3
# Ninja for a new build tree (about half the build time of the Makefile
# generator here); an existing tree keeps the generator it was made with.
NEW_TREE = $(if $(wildcard $(1)/CMakeCache.txt),,-G Ninja)
CONFIGURE = cmake -S . -B $(BUILD) $(call NEW_TREE,$(BUILD)) -DCMAKE_CXX_COMPILER=$(CXX) \
	  -DCMAKE_BUILD_TYPE=Release -DNHI_NATIVE=$(NATIVE) -DNHI_PYTHON=ON -DPython3_EXECUTABLE=$(PYTHON)
# The runner, the studies, the benchmark and the Python module.
build: deps
	$(CONFIGURE)
	cmake --build $(BUILD) -j$(JOBS) --target nhi_experiments nhi_python

# A figure or study target asked for directly builds the binaries if they are missing.
$(BUILD)/bin/%:
	$(MAKE) build

# The test executables, the Python module, and the runner, studies and
# benchmark that the command-line tests start (the rest of make build).
test: deps
	$(CONFIGURE)
	cmake --build $(BUILD) -j$(JOBS) --target nhi_tests
	ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

# Headers, libnhi.a, the runner, the CMake package and the Python module to
# PREFIX (no sudo: the prefix must be writable).
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

# The package used from outside (README "Use it from your code"): install the
# build tree's library, headers, runner and Python module to a temporary
# prefix, build examples/ out of tree against it (its build time is printed),
# run each example and the Python one, and check that the README's snippets
# are the examples' code.  After make test it builds nothing in $(BUILD).
EXAMPLES := user_system plain_loop odeint_interop
examples: deps
	$(CONFIGURE)
	cmake --build $(BUILD) -j$(JOBS) --target nhi nhi_cli nhi_python
	d=$$(mktemp -d) && trap 'rm -rf "$$d"' EXIT && set -e && \
	cmake --install $(BUILD) --prefix $$d/prefix > $$d/install.log && \
	cmake -S examples -B $$d/build -G Ninja -DCMAKE_CXX_COMPILER=$(CXX) -DCMAKE_PREFIX_PATH=$$d/prefix \
	  > $$d/configure.log && \
	t0=$$(date +%s) && cmake --build $$d/build -j$(JOBS) && \
	echo "examples: built out of tree in $$(( $$(date +%s) - t0 )) s" && \
	for e in $(EXAMPLES); do echo "== examples/$$e"; $$d/build/$$e; done && \
	echo "== examples/python/fig1.py" && \
	PYTHONPATH=$$(echo $$d/prefix/lib*/python3*/dist-packages) $(PYTHON) examples/python/fig1.py \
	  experiments/scenes/particle_fig12.json $$d/fig1.png && \
	$(PYTHON) tests/readme_snippets.py README.md examples

# The whole suite under AddressSanitizer and UndefinedBehaviorSanitizer, in its
# own build tree (-O1 with line tables, for readable reports).
test-sanitize: deps
	cmake -S . -B $(BUILD)-sanitize $(call NEW_TREE,$(BUILD)-sanitize) -DCMAKE_CXX_COMPILER=$(CXX) \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DNHI_NATIVE=OFF -DNHI_SANITIZE=ON
	cmake --build $(BUILD)-sanitize -j$(JOBS) --target nhi_tests
	UBSAN_OPTIONS=print_stacktrace=1 ctest --test-dir $(BUILD)-sanitize --output-on-failure -j$(JOBS)

# libFuzzer on the scene loader and validator (tests/fuzz/fuzz_scene.cpp), with
# ASan and UBSan, for FUZZ_SECONDS; seeds are the scene files, new inputs go to
# $(BUILD)-fuzz/corpus.  A finding is saved as crash-*/leak-* in the current
# directory and the target exits non-zero.
FUZZ_SECONDS ?= 600
FUZZ_FLAGS := -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
fuzz: deps
	cmake -S . -B $(BUILD)-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DNHI_NATIVE=OFF -DNHI_FUZZ=ON -DCMAKE_CXX_FLAGS="$(FUZZ_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
	cmake --build $(BUILD)-fuzz -j$(JOBS) --target fuzz_scene
	mkdir -p $(BUILD)-fuzz/corpus
	$(BUILD)-fuzz/bin/fuzz_scene -max_total_time=$(FUZZ_SECONDS) -max_len=2048 -print_final_stats=1 \
	  -dict=tests/fuzz/scene.dict $(BUILD)-fuzz/corpus experiments/scenes tests/fuzz/seeds

reproduce: build
	$(MAKE) --no-print-directory check-sweep
	$(MAKE) -j$(JOBS) figures

# ---- The large tables: regenerated by make sweep, checked by make reproduce --
# Long runs (long_horizon), many initial states (states, the fate map) and the
# timed studies (work_precision, the benchmark) take most of the CPU time of
# the results; make reproduce keeps the committed ones and refuses any made
# before the last change to the code it depends on (experiments/tools/check_fresh.sh).
# Their rules exist only under make sweep (SWEEP=1), so that a newer binary
# does not make reproduce run them again.
SWEEP_RESULTS := results/long_horizon.json results/states.json results/fate_map.json results/fate_map_roots.json \
                 results/work_precision.json results/step_costs.json
check-sweep:
	experiments/tools/check_fresh.sh results/long_horizon.json experiments/studies/study_long_horizon.cpp
	experiments/tools/check_fresh.sh results/states.json experiments/studies/study_states.cpp
	experiments/tools/check_fresh.sh results/fate_map.json experiments/studies/study_fate_map.cpp
	experiments/tools/check_fresh.sh results/fate_map_roots.json experiments/studies/study_fate_map.cpp
	experiments/tools/check_fresh.sh results/work_precision.json experiments/studies/study_work_precision.cpp
	experiments/tools/check_fresh.sh results/step_costs.json experiments/studies/bench_steps.cpp
sweep: build
	$(MAKE) -j$(JOBS) SWEEP=1 sweep-results
	$(MAKE) -j$(JOBS) study-long-horizon study-work-precision fate-map-figures

# ---- Paper Figures 1-4: particle (1-2) and robot (3-4) at h = 0.2 -----------
RUNS := $(foreach s,particle_fig12 robot_fig34,$(foreach m,dla rk4 benchmark,results/$(s)_$(m).json))
FIGURES := plots/fig1_particle_energy.png plots/fig2_particle_constraint.png \
           plots/fig3_robot_energy.png plots/fig4_robot_constraint.png

# ---- Companions to Figures 1-4 with the methods after the paper (issue 11) ----
COMPANION_RUNS := $(foreach s,particle_fig12 robot_fig34,results/$(s)_mp06.json results/$(s)_mp06tj.json)
COMPANION_FIGURES := plots/fig1b_particle_energy.png plots/fig2b_particle_constraint.png \
                     plots/fig3b_robot_energy.png plots/fig4b_robot_constraint.png
results/%_mp06.json: experiments/scenes/%.json $(NHI)
	$(NHI) run $< --set method=mp06 -o $@
results/%_mp06tj.json: experiments/scenes/%.json $(NHI)
	$(NHI) run $< --set method=mp06 --set composition=triple_jump -o $@
plots/fig1b_particle_energy.png: plots/energy_new.gp $(STYLE) $(filter results/particle_fig12_%,$(RUNS) $(COMPANION_RUNS))
	$(call PLOT,results/particle_fig12,Figure 1b: nonholonomic particle,1)
plots/fig2b_particle_constraint.png: plots/constraint_new.gp $(STYLE) $(filter results/particle_fig12_%,$(RUNS) $(COMPANION_RUNS))
	$(call PLOT,results/particle_fig12,Figure 2b: nonholonomic particle,1)
plots/fig3b_robot_energy.png: plots/energy_new.gp $(STYLE) $(filter results/robot_fig34_%,$(RUNS) $(COMPANION_RUNS))
	$(call PLOT,results/robot_fig34,Figure 3b: mobile robot,2)
plots/fig4b_robot_constraint.png: plots/constraint_new.gp $(STYLE) $(filter results/robot_fig34_%,$(RUNS) $(COMPANION_RUNS))
	$(call PLOT,results/robot_fig34,Figure 4b: mobile robot,2)

# One figure per study and registered scene (see STUDY below).
STUDY_TARGETS := study-convergence study-long-horizon study-stability study-work-precision study-poincare \
                 study-global-error

GEOMETRY_FIGURES := plots/geometry_momentum.png plots/geometry_extrinsic.png

figures: $(FIGURES) $(COMPANION_FIGURES) $(STUDY_TARGETS) $(GEOMETRY_FIGURES) fate-map-figures results/summary.md readme-tables

plots/method_styles.gp: $(NHI)
	$(NHI) list --gnuplot > $@.tmp && { cmp -s $@.tmp $@ && rm $@.tmp || mv $@.tmp $@; }

# results/SCENE_METHOD.json from experiments/scenes/SCENE.json
.SECONDEXPANSION:
$(RUNS): results/%.json: experiments/scenes/$$(word 1,$$(subst _, ,$$*))_$$(word 2,$$(subst _, ,$$*)).json $(NHI)
	$(NHI) run $< --set method=$(lastword $(subst _, ,$*)) -o $@

PLOT = gnuplot -e "stem='$(1)'; out='$@'; label='$(2)'; m=$(3)" $<
plots/fig1_particle_energy.png: plots/energy.gp $(STYLE) $(filter results/particle_fig12_%,$(RUNS))
	$(call PLOT,results/particle_fig12,Figure 1: nonholonomic particle,1)
plots/fig2_particle_constraint.png: plots/constraint.gp $(STYLE) $(filter results/particle_fig12_%,$(RUNS))
	$(call PLOT,results/particle_fig12,Figure 2: nonholonomic particle,1)
plots/fig3_robot_energy.png: plots/energy.gp $(STYLE) $(filter results/robot_fig34_%,$(RUNS))
	$(call PLOT,results/robot_fig34,Figure 3: mobile robot,2)
plots/fig4_robot_constraint.png: plots/constraint.gp $(STYLE) $(filter results/robot_fig34_%,$(RUNS))
	$(call PLOT,results/robot_fig34,Figure 4: mobile robot,2)

# ---- Studies (issue 4): one executable, one JSON, one script each -------------
SCENES := $(wildcard experiments/scenes/*.json)

# $(call STUDY,name,target): results/name.json from build/bin/study_name, and
# plots/name_SCENE.png from plots/name.gp for every scene the JSON holds (every
# registered system: the list comes from the result, not from this file).
define STUDY
.PHONY: $(2)
$(2): results/$(1).json
	$$(MAKE) --no-print-directory $$$$(jq -r '.scenes | keys_unsorted[] | "plots/$(1)_" + . + ".png"' $$<)
# The script reads everything it needs from the result in one jq pass
# (jq_script, plots/style.gp).  A failure of jq or gnuplot fails the target;
# gnuplot's "Skipping data file" warnings (a series empty for a scene) are dropped.
plots/$(1)_%.png: plots/$(1).gp $(STYLE) results/$(1).json
	log=$$$$(mktemp) && { gnuplot -e "file='results/$(1).json'; scene='$$*'; out='$$@'" $$< > $$$$log 2>&1; \
	  rc=$$$$?; grep -v Skipping $$$$log; rm -f $$$$log; exit $$$$rc; }
endef
$(eval $(call STUDY,convergence,study-convergence))
$(eval $(call STUDY,long_horizon,study-long-horizon))
$(eval $(call STUDY,stability,study-stability))
$(eval $(call STUDY,work_precision,study-work-precision))
$(eval $(call STUDY,poincare,study-poincare))
$(eval $(call STUDY,global_error,study-global-error))

results/convergence.json results/stability.json results/geometry.json results/poincare.json \
    results/global_error.json: results/%.json: $(BUILD)/bin/study_% $(SCENES)
	$< --threads $(JOBS) -o $@

# ---- The geometry of the discrete flow (issue 5): eq. 24, eq. 17, Remark 3.3 ---
.PHONY: study-geometry
study-geometry: $(GEOMETRY_FIGURES)
plots/geometry_%.png: plots/geometry_%.gp $(STYLE) results/geometry.json
	log=$$(mktemp) && { gnuplot -e "file='results/geometry.json'; out='$@'" $< > $$log 2>&1; \
	  rc=$$?; grep -v Skipping $$log; rm -f $$log; exit $$rc; }

ifdef SWEEP
sweep-results: $(SWEEP_RESULTS)
results/long_horizon.json results/states.json: results/%.json: $(BUILD)/bin/study_% $(SCENES)
	$< --threads $(JOBS) -o $@
# The timed studies run after the others (order-only prerequisites), so that
# no other job shares the two cores while they measure CPU time.
results/work_precision.json: $(BUILD)/bin/study_work_precision $(SCENES) \
    | results/long_horizon.json results/states.json results/fate_map.json results/fate_map_roots.json
	$< --threads $(JOBS) -o $@

# Micro-benchmarks: ns per step, and the DLA step over the analytic floor.
# Two shards at once, one per core, each holding whole scenes (bench_steps
# --shard: every ratio to RK4 is measured in one process); five repetitions
# of >= 0.1 s per row, the fastest kept.
BENCH_FLAGS := --benchmark_min_time=0.1 --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
# The shards' results and logs go to a temporary directory, never results/.
results/step_costs.json: $(BUILD)/bin/bench_steps | results/work_precision.json
	d=$$(mktemp -d) && { \
	  $< $(BENCH_FLAGS) --shard 0/2 -o $$d/0.json > $$d/0.log 2>&1 & pid=$$!; \
	  $< $(BENCH_FLAGS) --shard 1/2 -o $$d/1.json > $$d/1.log 2>&1; rc1=$$?; wait $$pid; rc0=$$?; \
	  cat $$d/0.log $$d/1.log; \
	  if [ $$rc0 -ne 0 ] || [ $$rc1 -ne 0 ]; then echo "bench_steps failed" >&2; rc=1; \
	  else $< --merge $$d/0.json $$d/1.json -o $@; rc=$$?; fi; rm -rf $$d; exit $$rc; }
endif

# Markdown tables of the results (results/summary.md), and the README's
# generated tables copied from it and from `nhi list --markdown`.
results/summary.md: experiments/tools/summarize.sh results/convergence.json results/long_horizon.json results/work_precision.json results/poincare.json \
    results/stability.json results/geometry.json results/fate_map.json results/fate_map_roots.json results/states.json \
    results/global_error.json results/step_costs.json \
    $(RUNS) $(COMPANION_RUNS) $(NHI)
	experiments/tools/summarize.sh results $(NHI) > $@.tmp && mv $@.tmp $@
readme-tables: results/summary.md $(NHI)
	d=$$(mktemp -d) && { $(NHI) list --markdown > $$d/list.md && \
	  experiments/tools/readme_tables.sh results/summary.md $$d/list.md; rc=$$?; rm -rf $$d; exit $$rc; }

# ---- The fate map: h x epsilon x methods x 100 initial states on the contact
# oscillators, sharded over MPI ranks like every study.  RANKS=N runs it under
# mpirun with N ranks of THREADS threads each (default: one process of $(JOBS)
# threads); the result is the same JSON either way (stats aside).
RANKS ?= 1
THREADS ?= $(JOBS)
# Open MPI refuses to run as root (containers, CI) without this flag.
MPIRUN = mpirun $(if $(filter 0,$(shell id -u)),--allow-run-as-root,)
# Which root the implicit methods follow at h >= 1, with the method's own start
# and from the root continued from h -> 0, at epsilon = ROOT_VALUES (the study
# takes any list, e.g. ROOT_VALUES=0.1,0.3,1,3).
ROOT_VALUES ?= 0.1
ifdef SWEEP
results/fate_map.json: $(BUILD)/bin/study_fate_map $(SCENES)
	$(if $(filter-out 1,$(RANKS)),$(MPIRUN) -np $(RANKS),) $< --threads $(THREADS) -o $@
results/fate_map_roots.json: $(BUILD)/bin/study_fate_map $(SCENES) | results/fate_map.json
	$(if $(filter-out 1,$(RANKS)),$(MPIRUN) -np $(RANKS),) $< --roots --h-min 1 --values $(ROOT_VALUES) \
	  --threads $(THREADS) -o $@
endif
.PHONY: fate-map-figures
fate-map-figures: results/fate_map.json
	$(MAKE) --no-print-directory $$(jq -r '.scenes | keys_unsorted[] | "plots/fate_map_" + . + ".png"' $<)
plots/fate_map_%.png: plots/fate_map.gp $(STYLE) results/fate_map.json
	gnuplot -e "file='results/fate_map.json'; scene='$*'; out='$@'" $<
# Its run time with 1, 2 and 4 ranks of one thread each (4 oversubscribes
# this machine's two cores: a correctness check, not a speed-up).
sweep-scaling: $(BUILD)/bin/study_fate_map
	experiments/tools/sweep_scaling.sh $< "$(MPIRUN)" results/fate_map_scaling.json 1 2 4

clean:
	rm -rf $(BUILD)
