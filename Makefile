# bayeslight — thin wrapper around CMake. Every target first installs missing Debian packages (apt-get).
#   make          build build/bayeslight (Release)
#   make run      build, render the demo scene with the bayes sampler, write image + error-vs-time report
#   make test     build and run the whole test suite (Catch2 through CTest), golden images included
#   make bench    benchmarks (long renders, equal-time tables, microbenchmarks)
#   make golden   regenerate golden/ (only for a deliberate change of output; say why in the commit)
#   make clean    remove build outputs
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
PKGS := g++ make cmake pkg-config python3 libembree-dev libtinyobjloader-dev libstb-dev libpcg-cpp-dev catch2 \
        libtbb-dev libtinyexr-dev libcli11-dev nlohmann-json3-dev libbenchmark-dev
BIN := $(BUILD)/bayeslight
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build run test bench golden clean

all: build

deps:
	@missing=""; for p in $(PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  $(SUDO) apt-get update -qq && \
	  $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	fi

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

run: build
	@tools/demo.sh $(BIN)

bench: build
	@tools/bench.sh $(BIN) $(BUILD)

golden: build
	@tools/golden.sh $(BIN)

clean:
	rm -rf $(BUILD)
