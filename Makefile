# bayeslight — thin wrapper around CMake. Every target first installs missing Debian packages (apt-get).
#   make          build build/bayeslight (Release)
#   make run      build, render the demo scene with the bayes sampler, write image + error-vs-time report
#   make test     build and run the whole test suite (Catch2 through CTest), golden images included
#   make bench    benchmarks (long renders, equal-time tables, microbenchmarks)
#   make golden   regenerate golden/ (only for a deliberate change of output; say why in the commit)
#   make clean    remove build outputs
#   make fuzz           libFuzzer targets for every input parser (clang, build-fuzz/), FUZZ_SECONDS each (default 60)
#   make test-sanitize  the whole test suite and small renders under ASan + UBSan (build-sanitize/)
#   make test-tsan      ThreadSanitizer: renders and the threaded tests, with an instrumented oneTBB (build-tsan/;
#                       about 20 minutes on 2 cores; fetches oneTBB's Debian source, so not part of make test)
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
	rm -rf $(BUILD) $(FUZZ_BUILD) $(SANITIZE_BUILD) $(TSAN_BUILD)

# ---- Robustness (issue 5): fuzzing and sanitizers, each in its own build folder. -----------------------------
# make fuzz: installs clang + libFuzzer if missing, builds fuzz_{scene,obj,texture,image} (-DBAYESLIGHT_FUZZ=ON)
# and fuzzes each for FUZZ_SECONDS; new crashes land in fuzz/crashes/<target>/ (see fuzz/README.md).
FUZZ_SECONDS ?= 60
FUZZ_BUILD ?= build-fuzz
FUZZ_PKGS := clang libclang-rt-14-dev zlib1g-dev
FUZZ_TARGETS := fuzz_scene fuzz_obj fuzz_texture fuzz_image fuzz_make_seeds
SANITIZE_BUILD ?= build-sanitize

.PHONY: fuzz fuzz-build test-sanitize

fuzz-build: deps
	@$(MAKE) --no-print-directory deps PKGS="$(FUZZ_PKGS)"
	@cmake -S . -B $(FUZZ_BUILD) -DCMAKE_CXX_COMPILER=clang++ -DBAYESLIGHT_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target $(FUZZ_TARGETS)

fuzz: fuzz-build
	fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

# make test-sanitize: builds with -DBAYESLIGHT_SANITIZE=ON (ASan + UBSan) and runs ctest plus small renders of every
# data/ scene with every sampler; prints how long each step took.
test-sanitize: deps
	tools/sanitize.sh $(SANITIZE_BUILD) $(JOBS)

# make test-tsan: tools/tsan.sh (dpkg-dev unpacks the oneTBB source it fetches).
TSAN_BUILD ?= build-tsan
.PHONY: test-tsan
test-tsan: deps
	@$(MAKE) --no-print-directory deps PKGS="dpkg-dev"
	tools/tsan.sh $(TSAN_BUILD) $(JOBS)
