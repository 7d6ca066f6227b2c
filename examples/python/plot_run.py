"""Plots a run of a virtual drive with matplotlib, where matplotlib is installed: enable, run up
to 1500 rpm, quick stop, as velocity over time with the drive's state and torque beneath it.

    PYTHONPATH=build/release/python python3 examples/python/plot_run.py [out.png]

Without matplotlib it says so and exits 0 (the package itself needs neither matplotlib nor NumPy);
`cia402.sim.Trace.to_svg()` draws the simulator's own plot with no dependency at all.
"""
import sys

from cia402 import sim


def run():
    """The trace of the run, one row per 1 ms cycle."""
    m = sim.Machine(axes=1, trace=[0])
    axis = m.axis(0)
    axis.control_word = 0x06
    m.advance(10)
    axis.control_word = 0x0F
    m.advance(10)
    axis[0x60FF] = 1500        # after T4, which clears the set-points
    m.advance(2000)
    axis.control_word = 0x02   # quick stop: the 0x6085 ramp, then SWITCH ON DISABLED
    m.advance(500)
    return m.trace(0)


def main(argv):
    out = argv[1] if len(argv) > 1 else "run.png"
    try:
        import matplotlib
    except ImportError:
        print("plot_run: matplotlib is not installed (apt-get install python3-matplotlib): nothing plotted")
        return 0
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    trace = run()
    seconds = [t / 1e6 for t in trace["time_us"]]
    states = list(trace["state"])
    figure, (speed, state, torque) = plt.subplots(3, 1, sharex=True, figsize=(9, 6),
                                                  gridspec_kw={"height_ratios": [4, 2, 1]})
    speed.plot(seconds, list(trace["velocity_rpm"]), label="velocity (0x606C)")
    speed.plot(seconds, list(trace["target_rpm"]), "--", label="target (0x60FF)")
    speed.set_ylabel("rpm")
    speed.legend(loc="upper left")
    names = sorted(set(states), key=states.index)  # in the order the run visits them
    state.step(seconds, [names.index(s) for s in states], where="post")
    state.set_yticks(range(len(names)), names, fontsize=7)
    torque.step(seconds, [int(t) for t in trace["torque"]], where="post", color="tab:red")
    torque.set_yticks([0, 1], ["off", "on"], fontsize=7)
    torque.set_ylabel("torque", fontsize=8)
    torque.set_xlabel("s")
    figure.tight_layout()
    figure.savefig(out, dpi=100)
    print(f"plot_run: wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
