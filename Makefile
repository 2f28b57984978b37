# Two commands on a fresh Debian machine:
#   make test        build and run the test suite (what CI runs)
#   make reproduce   regenerate results/*.json and the figures in plots/
# Both first install any missing Debian package (target deps).

DEB_PACKAGES := cmake g++ make libeigen3-dev libceres-dev libsundials-dev \
                nlohmann-json3-dev libcli11-dev libgtest-dev gnuplot-nox jq
BUILD ?= build
NHI := $(BUILD)/bin/nhi
JOBS ?= 2

.PHONY: all deps build test reproduce figures clean
all: build

deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "deps: installing$$missing"; \
	  if [ "$$(id -u)" -eq 0 ]; then SUDO=""; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -q && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing; \
	fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j$(JOBS)

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

reproduce: build
	$(MAKE) -j$(JOBS) figures

# ---- Paper Figures 1-2: the nonholonomic particle at h = 0.2 ----------------
PARTICLE_FIG12 := $(foreach m,dla rk4 benchmark,results/particle_fig12_$(m).json)
FIGURES := plots/fig1_particle_energy.png plots/fig2_particle_constraint.png

figures: $(FIGURES)

results/particle_fig12_%.json: experiments/scenes/particle_fig12.json $(NHI)
	$(NHI) run $< --set method=$* -o $@

plots/fig1_particle_energy.png: plots/fig1_particle_energy.gp plots/style.gp $(PARTICLE_FIG12)
	gnuplot $<

plots/fig2_particle_constraint.png: plots/fig2_particle_constraint.gp plots/style.gp $(PARTICLE_FIG12)
	gnuplot $<

clean:
	rm -rf $(BUILD)
