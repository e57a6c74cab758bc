#!/usr/bin/env bash
# sanitize.sh BUILD_DIR [JOBS]: `make test-sanitize`. Builds everything with AddressSanitizer + UBSan
# (-DBAYESLIGHT_SANITIZE=ON, -O2 -g) into BUILD_DIR, runs the whole CTest suite under it, then small renders of
# every data/ scene (direct and path) with every sampler (32x24, 4 spp) under it. Any sanitizer report fails the
# run (UBSan is built with -fno-sanitize-recover; ASan exits non-zero), as does any render that does not exit 0.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-sanitize}
jobs=${2:-2}
start=$(date +%s)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBAYESLIGHT_SANITIZE=ON >/dev/null
cmake --build "$build" -j "$jobs"
built=$(date +%s)

# Leaks are checked (LeakSanitizer is part of ASan on x86-64 Linux); stack-use-after-return is not (it makes
# TBB worker stacks expensive for little gain in this code). abort_on_error gives a core-style stop in CTest.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1:detect_invalid_pointer_pairs=0}
# LeakSanitizer needs ptrace; some containers forbid it (LSan then aborts every process). Probe once with the
# built binary and, if leak checking cannot run here, say so and go on with ASan + UBSan alone.
if ! "$build/bayeslight" --help >/dev/null 2>"$build/lsan_probe.txt"; then
  if grep -q "LeakSanitizer has encountered a fatal error" "$build/lsan_probe.txt"; then
    echo "sanitize: LeakSanitizer cannot run on this machine (no ptrace); leak checks off" >&2
    export ASAN_OPTIONS=${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}
  fi
fi
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

(cd "$build" && ctest --output-on-failure -j "$jobs")
tested=$(date +%s)

out=$(mktemp -d "${TMPDIR:-/tmp}/bayeslight_sanitize_XXXXXX")
trap 'rm -rf "$out"' EXIT
samplers="uniform power bvh bound donikian bayes"
renders=0
for scene in data/*/direct.json data/*/path.json; do
  for sampler in $samplers; do
    name=$(basename "$(dirname "$scene")")_$(basename "$scene" .json)_$sampler
    if ! "$build/bayeslight" render "$scene" --sampler "$sampler" --width 32 --height 24 --spp 4 --threads 2 \
        --quiet -o "$out/$name.exr" --log "$out/$name.csv" 2>"$out/$name.err"; then
      echo "sanitize: render FAILED: $scene --sampler $sampler" >&2
      cat "$out/$name.err" >&2
      exit 1
    fi
    renders=$((renders + 1))
  done
done
done_at=$(date +%s)
echo "sanitize: OK — build $((built - start)) s, ctest $((tested - built)) s, $renders renders $((done_at - tested)) s," \
     "total $((done_at - start)) s"
