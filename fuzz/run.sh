#!/usr/bin/env bash
# run.sh BUILD_DIR SECONDS [TARGET...]: the run step of `make fuzz`. Fuzzes each target (default: scene obj
# texture image) for SECONDS of wall time, one after the other (one process each: CI has 2 cores). New inputs
# go to BUILD_DIR/corpus/<target> (the committed fuzz/corpus/<target> is read, never written); crashes, leaks,
# timeouts and out-of-memory inputs go to fuzz/crashes/<target>/. After a crash the target is restarted for the
# rest of its time (at most 5 times), so one run can collect several distinct crashes.
# Exit status: 0 when no target found anything, 1 otherwise. Per-target logs: BUILD_DIR/fuzz_<target>.log.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: fuzz/run.sh BUILD_DIR SECONDS [TARGET...]}
seconds=${2:?usage: fuzz/run.sh BUILD_DIR SECONDS [TARGET...]}
shift 2
targets=${*:-scene obj texture image}
found=0
total_execs=0
for t in $targets; do
  bin=$build/fuzz_$t
  [ -x "$bin" ] || { echo "fuzz: $bin is not built" >&2; exit 2; }
  mkdir -p "$build/corpus/$t" "fuzz/crashes/$t"
  dict=()
  [ -f "fuzz/$t.dict" ] && dict=("-dict=fuzz/$t.dict")
  log=$build/fuzz_$t.log
  : >"$log"
  end=$(($(date +%s) + seconds))
  execs=0
  for attempt in 1 2 3 4 5 6; do
    left=$((end - $(date +%s)))
    [ "$left" -ge 1 ] || break
    before=$(wc -l <"$log")
    # -timeout: one input may take 30 s (ASan + a huge valid image); -rss_limit_mb: the parsers' own limits
    # allow ~1-2 GiB for a legal input, more is a finding.
    "$bin" -max_total_time="$left" -timeout=30 -rss_limit_mb=3072 -print_final_stats=1 \
      -artifact_prefix="fuzz/crashes/$t/" "${dict[@]}" "$build/corpus/$t" "fuzz/corpus/$t" >>"$log" 2>&1
    status=$?
    n=$(tail -n +"$((before + 1))" "$log" | grep -a '^stat::number_of_executed_units' | tail -1 | awk '{print $2}')
    execs=$((execs + ${n:-0}))
    [ "$status" -eq 0 ] && break
    found=1
    echo "fuzz: $t stopped with status $status (see $log):" >&2
    tail -n +"$((before + 1))" "$log" | grep -a -m4 -E '^==[0-9]+==ERROR|^SUMMARY|escaped|Test unit written' >&2
  done
  total_execs=$((total_execs + execs))
  echo "fuzz: $t: $execs executions in ${seconds} s, $(ls "$build/corpus/$t" | wc -l) new corpus inputs"
done
echo "fuzz: $total_execs executions in all; crashes (if any) in fuzz/crashes/"
ls -R fuzz/crashes | grep -v -e '^fuzz/crashes' -e '^$' | sed 's/^/  /' || true
exit $found
