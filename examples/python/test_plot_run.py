"""The plotting example runs: it writes a PNG where matplotlib is installed and says it skipped
where it is not (CI installs no matplotlib; the package does not need it)."""
import importlib.util
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).parent


def test_plot_run_writes_a_png_or_says_why_not(tmp_path):
    out = tmp_path / "run.png"
    done = subprocess.run([sys.executable, str(HERE / "plot_run.py"), str(out)],
                          capture_output=True, text=True, check=True)
    if importlib.util.find_spec("matplotlib") is None:
        assert "matplotlib is not installed" in done.stdout and not out.exists()
    else:
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "wrote" in done.stdout


def test_the_run_it_plots_enables_runs_up_and_quick_stops():
    sys.path.insert(0, str(HERE))
    import plot_run
    trace = plot_run.run()
    states = list(trace["state"])
    assert "OPERATION_ENABLED" in states and states[-1] == "SWITCH_ON_DISABLED"
    assert max(trace["velocity_rpm"]) == 1500
