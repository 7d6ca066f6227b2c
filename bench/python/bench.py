"""The Python binding's overhead: steps per second of cia402.Drive.step and of a 1,000-axis
cia402.sim.Machine advanced from Python, beside the same work in C++ (the release preset's Google
Benchmark programs, run here in the same session), as ratios. Not a test: figures to read.

    python3 bench/python/bench.py [BUILD_DIR]     # default build/release

Figures move with the machine's load (a shared 2-core machine can vary 1.7x run to run): compare
the ratios of one run, not absolute figures across runs.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build/release")
sys.path.insert(0, os.path.join(build, "python"))

import cia402  # noqa: E402
from cia402 import sim  # noqa: E402

AXES = 1000
CYCLES = 10_000


def best_of(runs, measure):
    """The fastest of `runs` measurements (each returns work units per second)."""
    return max(measure() for _ in range(runs))


def drive_steps_per_s(with_keyword):
    d = cia402.Drive()
    d.settle(control_word=0x06)
    d.settle(control_word=0x0F)
    n = 200_000
    step = d.step
    t0 = time.perf_counter()
    if with_keyword:
        for _ in range(n):
            step(control_word=0x0F)
    else:
        for _ in range(n):
            step()
    return n / (time.perf_counter() - t0)


def csp_machine():
    m = sim.Machine(axes=AXES)
    m.write(0x6060, 8)
    m.write(0x6040, 0x06)
    m.advance(3)
    m.write(0x6040, 0x0F)
    m.advance(60)
    return m


def ramp(c):
    """The C++ bench's set-point: 20 increments a ms, turning every 2 s."""
    leg = c % 4000
    return 20 * leg if leg < 2000 else 20 * (4000 - leg)


def machine_write_and_step_per_s(numpy):
    """Each cycle from Python: 0x607A written to every axis (one call), then one step."""
    m = csp_machine()
    offsets = numpy.arange(AXES, dtype=numpy.int64) if numpy else list(range(AXES))
    rows = [offsets + ramp(c) if numpy else [ramp(c) + i for i in offsets] for c in range(CYCLES)]
    t0 = time.perf_counter()
    for row in rows:
        m.write(0x607A, row)
        m.step()
    return AXES * CYCLES / (time.perf_counter() - t0)


def machine_stream_per_s(numpy):
    """The same set-points handed over at once (Machine.stream, the GIL released)."""
    m = csp_machine()
    if numpy:
        table = numpy.arange(AXES, dtype=numpy.int64)[None, :] + numpy.array(
            [ramp(c) for c in range(CYCLES)], dtype=numpy.int64)[:, None]
    else:
        table = [[ramp(c) + i for i in range(AXES)] for c in range(CYCLES)]
    t0 = time.perf_counter()
    m.stream(0x607A, table)
    return AXES * CYCLES / (time.perf_counter() - t0)


def machine_advance_per_s():
    """1,000 pv axes turning, each at its own speed, as the C++ sim_axis_steps enables them:
    advance() alone."""
    m = sim.Machine(axes=AXES)
    m.write(0x6040, 0x06)
    m.advance(3)
    m.write(0x6040, 0x0F)
    m.advance(3)
    m.write(0x60FF, [500 + i % 1000 for i in range(AXES)])
    m.advance(400)  # past the brake release and the ramp-up
    t0 = time.perf_counter()
    m.advance(CYCLES)
    return AXES * CYCLES / (time.perf_counter() - t0)


def google_benchmark(program, pattern):
    """The runs of a release benchmark, from its JSON file (cia402_bench prints ratios of its own)."""
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([os.path.join(build, "bench", program), f"--benchmark_filter={pattern}",
                        "--benchmark_repetitions=3", f"--benchmark_out={out.name}",
                        "--benchmark_out_format=json"], capture_output=True, check=True)
        runs = json.load(open(out.name))["benchmarks"]
    return [b for b in runs if b.get("run_type") == "iteration"]


def main():
    try:
        import numpy
    except ImportError:
        numpy = None
    cpp_step = google_benchmark("cia402_bench", "^drive_step_steady/cia402$")
    cpp_step_per_s = max(1e9 / b["real_time"] for b in cpp_step)
    cpp_csp = google_benchmark("cia402_sim_bench", "^sim_1000_axes_csp_1khz/threads:1/master_in_step:0")
    cpp_csp_per_s = max(b["axis_steps_per_s"] for b in cpp_csp)
    cpp_pv = google_benchmark("cia402_sim_bench", "^sim_axis_steps/1000/")
    cpp_pv_per_s = max(b["axis_steps_per_s"] for b in cpp_pv)

    rows = [
        ("Drive.step() (inputs held)", best_of(3, lambda: drive_steps_per_s(False)), cpp_step_per_s,
         "drive_step_steady/cia402"),
        ("Drive.step(control_word=...)", best_of(3, lambda: drive_steps_per_s(True)), cpp_step_per_s,
         "drive_step_steady/cia402"),
        (f"Machine({AXES}) write(0x607A) + step() a cycle", best_of(3, lambda: machine_write_and_step_per_s(numpy)),
         cpp_csp_per_s, "sim_1000_axes_csp_1khz threads:1"),
        (f"Machine({AXES}).stream(0x607A, table)", best_of(3, lambda: machine_stream_per_s(numpy)),
         cpp_csp_per_s, "sim_1000_axes_csp_1khz threads:1"),
        (f"Machine({AXES}).advance() (pv, turning)", best_of(3, machine_advance_per_s),
         cpp_pv_per_s, "sim_axis_steps/1000"),
    ]
    print(f"cia402 {cia402.__version__}, Python {sys.version.split()[0]}, NumPy {'yes' if numpy else 'no'}; "
          f"best of 3 (C++: best of 3 repetitions)")
    print(f"{'from Python':46} {'steps/s':>9} {'C++':>9} {'Python/C++':>10}  the same in C++")
    for name, python_rate, cpp_rate, cpp_name in rows:
        print(f"{name:46} {python_rate:9.3g} {cpp_rate:9.3g} {python_rate / cpp_rate:10.3f}  {cpp_name}")
    print("(a machine's steps are axis-steps: axes x cycles)")


if __name__ == "__main__":
    main()
