#!/usr/bin/env bash
# tsan.sh BUILD_DIR [JOBS]: `make test-tsan` (not part of `make test`: about 20 minutes on 2 cores). Builds the
# renderer with ThreadSanitizer (-DBAYESLIGHT_TSAN=ON) into BUILD_DIR, against a oneTBB of the installed version built
# with TSan too (Debian's is not instrumented: TSan cannot see the ordering its tasks give, and one small render gave
# 207 false reports), then renders every data/ scene with every sampler on 2 threads and runs the threaded tests
# (thread counts, determinism, progress, light tree, animations, checkpoints' signals). Any report fails the run.
# The oneTBB source comes from the machine's own Debian mirror (deb-src of its sources, in a private apt state:
# the system's is not touched) and is built once into BUILD_DIR/onetbb-build.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-tsan}
jobs=${2:-2}
root=$(pwd)
start=$(date +%s)
mkdir -p "$build"
build=$(cd "$build" && pwd)

tbb_build=$build/onetbb-build
if [ ! -f "$tbb_build/done" ]; then
  ver=$(dpkg-query -W -f='${Version}' libtbb12)
  apt_dir=$build/apt
  rm -rf "$apt_dir" "$build/onetbb-src"
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial" "$build/onetbb-src"
  # deb-src lines for the Debian sources the machine uses (deb822 files and classic lists).
  python3 - "$apt_dir/sources.list" <<'PY'
import glob, sys
lines = []
for path in glob.glob('/etc/apt/sources.list.d/*.sources'):
    for stanza in open(path).read().split('\n\n'):
        f = {}
        for line in stanza.splitlines():
            if ':' in line and not line.startswith('#'):
                k, v = line.split(':', 1)
                f[k.strip()] = v.strip()
        if 'deb' in f.get('Types', '').split() and 'debian' in f.get('URIs', ''):
            for uri in f['URIs'].split():
                lines.append('deb-src [trusted=yes] %s %s %s' % (uri, f.get('Suites', ''), f.get('Components', '')))
for path in ['/etc/apt/sources.list'] + glob.glob('/etc/apt/sources.list.d/*.list'):
    try:
        for line in open(path):
            w = line.split()
            if w and w[0] == 'deb' and 'debian' in line:
                lines.append('deb-src ' + ' '.join(w[1:]))
    except OSError:
        pass
open(sys.argv[1], 'w').write('\n'.join(lines) + '\n')
PY
  apt=(apt-get -q -o Dir::Etc::SourceList="$apt_dir/sources.list" -o Dir::Etc::SourceParts=/nonexistent
       -o Dir::State::Lists="$apt_dir/lists" -o Dir::Cache="$apt_dir/cache" -o APT::Sandbox::User=root)
  echo "tsan: fetching the oneTBB $ver source" >&2
  "${apt[@]}" update >"$build/apt.log" 2>&1
  (cd "$build/onetbb-src" && "${apt[@]}" source "onetbb=$ver" >>"$build/apt.log" 2>&1)
  src=$(find "$build/onetbb-src" -mindepth 1 -maxdepth 1 -type d | head -n 1)
  echo "tsan: building oneTBB with ThreadSanitizer (about 2 minutes)" >&2
  cmake -S "$src" -B "$tbb_build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_SANITIZE=thread -DTBB_TEST=OFF \
    -DTBB_EXAMPLES=OFF -DTBB_STRICT=OFF >"$build/onetbb-cmake.log" 2>&1
  cmake --build "$tbb_build" -j "$jobs" >"$build/onetbb-build.log" 2>&1
  touch "$tbb_build/done"
fi
tbb_lib=$(dirname "$(find "$tbb_build" -name 'libtbb.so.12' -print -quit)")
tbb_built=$(date +%s)

echo "tsan: building the renderer with ThreadSanitizer (about 10 minutes on 2 cores)" >&2
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBAYESLIGHT_TSAN=ON >/dev/null
cmake --build "$build" -j "$jobs" --target bayeslight bayeslight_tests >"$build/build.log" 2>&1 ||
  { tail -n 30 "$build/build.log" >&2; exit 1; }
built=$(date +%s)

export LD_LIBRARY_PATH=$tbb_lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# The stock libtbb in its place floods with false reports: make sure the instrumented one is the one loaded.
if ! ldd "$build/bayeslight" | grep -q "libtbb.so.12 => $tbb_lib/"; then
  echo "tsan: the instrumented libtbb ($tbb_lib) is not the one loaded:" >&2
  ldd "$build/bayeslight" | grep tbb >&2
  exit 1
fi
reports=$build/tsan-reports
rm -rf "$reports"
mkdir -p "$reports"
# log_path keeps reports out of the output that tests compare; a report still makes the process exit 66.
export TSAN_OPTIONS="suppressions=$root/tools/tsan.supp history_size=4 log_path=$reports/report"

out=$(mktemp -d "${TMPDIR:-/tmp}/bayeslight_tsan_XXXXXX")
trap 'rm -rf "$out"' EXIT
failed=0
renders=0
for scene in data/*/direct.json data/*/path.json; do
  for sampler in uniform power bvh bound donikian bayes; do
    name=$(basename "$(dirname "$scene")")_$(basename "$scene" .json)_$sampler
    if ! timeout 600 "$build/bayeslight" render "$scene" --sampler "$sampler" --width 48 --height 36 --spp 8 \
        --threads 2 --quiet -o "$out/$name.exr" --log "$out/$name.csv" 2>"$out/$name.err"; then
      echo "tsan: render FAILED: $scene --sampler $sampler" >&2
      cat "$out/$name.err" >&2
      failed=1
    fi
    renders=$((renders + 1))
  done
done
rendered=$(date +%s)
for spec in "*thread*" "[determinism]" "[progress]" "[light_tree]" "[animation]"; do
  if ! (cd "$build" && timeout 1800 ./bayeslight_tests "$spec" >"$out/tests.txt" 2>&1); then
    echo "tsan: tests $spec FAILED:" >&2
    tail -n 30 "$out/tests.txt" >&2
    failed=1
  fi
done
tested=$(date +%s)
if compgen -G "$reports/report*" >/dev/null; then
  echo "tsan: ThreadSanitizer reports (in $reports):" >&2
  grep -h -A12 "WARNING: ThreadSanitizer" "$reports"/report* | head -n 80 >&2
  failed=1
fi
[ "$failed" -eq 0 ] || exit 1
echo "tsan: OK — oneTBB $((tbb_built - start)) s, build $((built - tbb_built)) s, $renders renders" \
     "$((rendered - built)) s, tests $((tested - rendered)) s, total $((tested - start)) s"
