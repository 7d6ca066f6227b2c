#!/usr/bin/env bash
# Builds cia402 and passes every test: the one command CI runs (.ci/run). As root on a fresh Debian 12
# it installs what it needs first. Exits non-zero at the first failure.
#   asan-ubsan preset: build + every CTest but the browser tests (the suite runs once, under the
#   sanitizers: a plain Debug run of the same tests would find nothing they do not); the tsan preset:
#   the page, CANopen and machine-thread tests under ThreadSanitizer; no-exceptions preset: the core
#   alone as C++17 without exceptions or RTTI; release preset: benchmarks (a short run, ratios to the
#   baseline), instructions per step (callgrind), whether g++ inlines the compiled step at -O2 and
#   -O3, the Cortex-M4 flash and RAM, the Python binding's overhead (bench/python), the state diagrams
#   against docs/diagrams, the browser tests of the page and the soak test (tests/soak/soak.py), both
#   on the release tool; the libFuzzer targets for 6 s each (tests/fuzz/run.sh); then
#   scripts/test-consumer.sh. The dev preset is the one to build by hand (README); CI does not build
#   it, so its 40-minute budget holds.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
started=$SECONDS
step="install-deps"
done_steps=()

joined() {
  if [ $# -eq 0 ]; then echo nothing; return; fi
  local out=$1; shift
  for s in "$@"; do out+="; $s"; done
  echo "$out"
}

finish() {
  local status=$?
  local elapsed=$((SECONDS - started))
  if [ "$status" -eq 0 ]; then
    printf '\ntest.sh: PASSED in %ss: %s\n' "$elapsed" "$(joined "${done_steps[@]}")"
  else
    printf '\ntest.sh: FAILED at step "%s" after %ss (exit %s); passed before it: %s\n' \
      "$step" "$elapsed" "$status" "$(joined "${done_steps[@]}")" >&2
  fi
}
trap finish EXIT

banner() { step=$1; step_started=$SECONDS; printf '\n======== %s ========\n' "$step"; }
# A step that passed, with the seconds it took: CI's budget is watched step by step.
passed() { done_steps+=("$1 ($((SECONDS - step_started)) s)"); }

# Tests in a preset: "N tests" from ctest's own listing.
test_count() { ctest --preset "$1" -N "${@:2}" | sed -n 's/^Total Tests: //p'; }

banner install-deps
bash scripts/install-deps.sh
passed "deps"

banner asan-ubsan
cmake --preset asan-ubsan
cmake --build --preset asan-ubsan
# A test that fails is run once more before the step fails: the bus tests over veth and loopback
# run on wall time against a 100 ms process-data watchdog and 300 ms heartbeat watches, which a
# sanitizer build on a loaded 2-core machine can miss once; a real failure fails both times.
# The browser tests check the page's JavaScript against a server: they run in the release step, on
# the release tool; under the sanitizers the server is held by page_tests and the HTTP runs.
ctest --preset asan-ubsan --repeat until-pass:2 -LE browser
passed "asan-ubsan: $(test_count asan-ubsan -LE browser) tests passed"

banner tsan
cmake --preset tsan
# Only what runs under it: a whole tsan build would double this step's time for binaries never run.
cmake --build --preset tsan --target page_tests canopen_tests sim_machine_tests
# The threaded parts: the page server (HTTP threads, the cycle thread, event streams) and the bus.
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build/tsan/tests/page/page_tests
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build/tsan/tests/canopen/canopen_tests
# A machine's axes on several threads.
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" build/tsan/tests/sim/sim_machine_tests
passed "tsan: page, CANopen and machine-thread tests"

banner no-exceptions
cmake --preset no-exceptions
cmake --build --preset no-exceptions
passed "no-exceptions core built"

banner release
cmake --preset release
# What this step runs: the benchmarks, the tool (diagrams) and the Python module where it builds; the
# release test binaries would only be built, never run (ctest runs the dev and asan-ubsan builds).
release_targets=(cia402 cia402_bench cia402_instructions cia402_sim_bench)
if grep -q '^cia402_python:' <(cmake --build --preset release --target help 2>/dev/null); then
  release_targets+=(cia402_python)
fi
cmake --build --preset release --target "${release_targets[@]}"
build/release/bench/cia402_bench --benchmark_min_time=0.05
# The step through every built-in profile, each judged against the bounds of 30 / 45 instructions.
for profile in cia402 no-quick-stop lexium32 s300-profibus ax2000-profibus; do
  bash bench/instructions/instructions.sh build/release/bench/cia402_instructions "$profile"
done
bash bench/inlining/inlined.sh
bash bench/cortex_m4/size.sh build/cortex-m4
# 1,000 csp axes at 1 kHz: realtime_factor on one thread and on two (printed; the machine is shared),
# and the instructions per axis-step, which are not.
build/release/bench/cia402_sim_bench --benchmark_filter=sim_1000_axes_csp
bash bench/instructions/sim_instructions.sh build/release/bench/cia402_sim_bench
# The Python binding's overhead: steps/s from Python beside the same in C++ (printed, not judged).
if [ -d build/release/python/cia402 ]; then
  /usr/bin/python3 bench/python/bench.py build/release
fi
bash scripts/diagrams.sh build/release/tools/cia402 --check
passed "release: bench, inlining, sim bench, Python bench, cortex-m4 size, diagrams"

banner browser
# The page in Chromium against the release tool's servers: only the tool is needed (built above).
ctest --preset release -L browser --repeat until-pass:2
passed "browser: $(test_count release -L browser) tests passed"

banner soak
python3 tests/soak/soak.py build/release/tools/cia402
passed "soak: bus and serve under load, nothing lost"

banner fuzz
# 6 s a target: each run starts from the corpus of what earlier runs found, so a short run still
# replays every input kept; CI stays under 40 minutes as targets are added. Longer runs by hand.
bash tests/fuzz/run.sh 6
passed "fuzz: every target, 6 s each"

banner consumer
# The install comes from the release tree the release step built (the tool links every installed
# library; the Python module was built there too), not from one more Release build.
CIA402_CONSUMER_BUILD=build/release bash scripts/test-consumer.sh
passed "consumer: find_package, pkg-config, add_subdirectory"
