"""cia402.sim.Trace: an axis's recorded cycles by column, and the files the simulator writes."""
import csv
import io

import pytest

import cia402
from cia402 import sim



def recorded():
    m = sim.Machine(axes=2, trace=[0])
    m.write(0x6040, 0x06)
    m.advance(5)
    m.write(0x6040, 0x0F)
    m.advance(5)
    m.write(0x60FF, 300)  # after T4, which clears the set-points
    m.advance(400)
    m.axis(0).inject_fault(0x2310)
    m.advance(200)  # the quick-stop ramp from 300 rpm, then the brake engages: T14
    return m


def as_list(column):
    return column.tolist() if hasattr(column, "tolist") else list(column)


def test_the_columns_are_the_csvs_with_0x60fd_after_them():
    t = recorded().trace(0)
    header = t.to_csv().splitlines()[0].split(",")
    assert list(sim.Trace.columns) == header + ["digital_inputs"]
    assert all(name in t for name in t.columns) and "nonsense" not in t


def test_every_column_holds_the_values_the_csv_prints():
    t = recorded().trace(0)
    rows = list(csv.DictReader(io.StringIO(t.to_csv())))
    assert len(rows) == len(t) == 610
    columns = {name: as_list(t[name]) for name in t.columns}
    for i, row in enumerate(rows):
        assert columns["time_us"][i] == int(row["time_us"])
        assert columns["state"][i] == row["state"]
        assert columns["velocity_rpm"][i] == pytest.approx(float(row["velocity_rpm"]), abs=1e-9)
        assert columns["torque"][i] == (row["torque"] == "1")
        assert columns["ramp"][i] == row["ramp"]
        assert columns["transition"][i] == (int(row["transition"]) if row["transition"] else -1)
        assert columns["statusword"][i] == int(row["statusword"], 16)
        assert columns["position"][i] == int(row["position"])


def test_the_trace_shows_the_run():
    t = recorded().trace(0)
    states = as_list(t["state"])
    transitions = [x for x in as_list(t["transition"]) if x != -1]
    assert transitions == [0, 1, 2, 3, 4, 13, 14]
    assert states[-1] == "FAULT" and max(as_list(t["velocity_rpm"])) == 300
    assert as_list(t["error_code"])[-1] == 0x2310 and as_list(t["fault_cause"])[-1] == 0x2310
    assert t.title == "axis 0" and t.profile == "cia402" and t.cycle_us == 1000


def test_the_numpy_path_gives_typed_arrays():
    numpy = pytest.importorskip("numpy")
    t = recorded().trace(0)
    assert sim.numpy_available()
    assert isinstance(t["velocity_rpm"], numpy.ndarray) and t["velocity_rpm"].dtype == numpy.float64
    assert t["time_us"].dtype == numpy.int64 and t["torque"].dtype == numpy.bool_
    assert (t["state"] == "FAULT").any() and t["time_us"].flags.writeable
    assert isinstance(sim.Machine(axes=3).read(0x6083), numpy.ndarray)
    assert set(t.as_dict()) == set(t.columns)


def test_an_axis_not_recorded_has_an_empty_trace_and_recording_starts_and_stops():
    m = sim.Machine(axes=2)
    assert len(m.trace(1)) == 0
    a = m.axis(1)
    a.record()
    m.advance(5)
    a.record(False)
    m.advance(5)
    assert len(a.trace()) == 5
    m.record(1)
    m.advance(2)
    assert len(m.trace(1)) == 7
    m.clear_trace(1)
    assert len(m.trace(1)) == 0


def test_the_other_files_of_a_trace():
    t = recorded().trace(0)
    assert t.to_jsonl().count("\n") == len(t)
    assert t.to_jsonl(every=100).count("\n") < len(t)
    vcd = t.to_vcd()
    assert "$timescale 1us $end" in vcd and "$var string" in vcd
    assert "$var string" not in t.to_vcd(standard=True)
    assert t.to_svg().lstrip().startswith("<svg")
    with pytest.raises(cia402.ArgumentError, match="velocity_rpm"):
        t["velocity"]
