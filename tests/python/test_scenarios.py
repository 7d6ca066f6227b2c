"""Scenarios from TOML: run from Python as `cia402 simulate` runs them."""
import pathlib
import subprocess

import pytest

import cia402
from cia402 import sim

SCENARIOS = sorted((pathlib.Path(__file__).parents[2] / "examples" / "scenarios").glob("*.toml"))


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_every_example_scenario_passes(path):
    result = sim.run_scenario(path)
    assert result.passed and bool(result) and result.failures == 0 and result.checks > 0
    assert result.expectations and all(not e.failed for e in result.expectations)
    assert len(result.trace) == sim.load_scenario(str(path)).cycles


def test_the_trace_is_the_one_cia402_simulate_writes(tool, examples, tmp_path):
    path = examples / "scenarios" / "quick-stop-2.toml"
    out = tmp_path / "trace.csv"
    subprocess.run([tool, "simulate", str(path), "--trace", str(out)], check=True, capture_output=True)
    assert sim.run_scenario(str(path)).trace.to_csv() == out.read_text()


def test_the_log_reads_as_cia402_simulate_prints_it(tool, examples):
    path = examples / "scenarios" / "quick-stop-2.toml"
    printed = subprocess.run([tool, "simulate", str(path)], capture_output=True, text=True).stdout
    result = sim.load_scenario(path).run(trace=False)
    assert result.trace is None
    for entry in result.log:
        assert str(entry) in printed


def test_a_failing_expectation_is_reported_not_raised():
    s = sim.Scenario.from_toml(
        'name = "wrong"\nduration = "50ms"\nevents = [{ at = "10ms", cw = 6 }]\n'
        'expect = [{ at = "40ms", state = "OPERATION_ENABLED" }]\n')
    assert (s.name, s.profile, s.cycle_us, s.cycles) == ("wrong", "cia402", 1000, 51)
    result = s.run()
    assert not result.passed and result.failures == 1
    assert [e.kind for e in result.failed] == ["expectation"] and "OPERATION_ENABLED" in result.failed[0].text
    assert result.failed[0].time_us == 40_000


def test_a_bad_scenario_is_refused_with_its_line():
    with pytest.raises(cia402.ScenarioError) as refused:
        sim.Scenario.from_toml('name = "x"\nduration = "50ms"\ncycle = "3ms"\n', "x.toml")
    e = refused.value
    assert e.line > 0 and e.source == "x.toml" and e.reason and "x.toml:" in str(e)
    with pytest.raises(cia402.ScenarioError) as missing:
        sim.run_scenario("/nonexistent.toml")
    assert missing.value.line == 0
