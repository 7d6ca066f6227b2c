"""Without NumPy every column and bulk read is a list, with the same values."""
import json
import os
import subprocess
import sys

SCRIPT = r"""
import json, sys
if sys.argv[1] == "hide":
    sys.modules["numpy"] = None  # import numpy now raises ImportError
from cia402 import sim
m = sim.Machine(axes=2, trace=[0])
m.write(0x6040, 6); m.advance(5); m.write(0x6040, 15); m.advance(5); m.write(0x60FF, 120); m.advance(300)
t = m.trace(0)
columns = {name: t[name] for name in t.columns}
reads = m.read(0x606C)
print(json.dumps({
    "numpy": sim.numpy_available(),
    "kinds": sorted({type(c).__name__ for c in columns.values()} | {type(reads).__name__, type(m.states()).__name__}),
    "columns": {k: [v.item() if hasattr(v, "item") else v for v in c] for k, c in columns.items()},
    "reads": [int(v) for v in reads],
}))
"""


def run(mode):
    out = subprocess.run([sys.executable, "-c", SCRIPT, mode], capture_output=True, text=True,
                         env=dict(os.environ), check=True)
    return json.loads(out.stdout)


def test_columns_are_lists_without_numpy_and_hold_the_same_values_as_with_it():
    hidden = run("hide")
    assert hidden["numpy"] is False and hidden["kinds"] == ["list"]
    assert hidden["reads"] == [120, 120]
    assert hidden["columns"]["state"][-1] == "OPERATION_ENABLED"
    assert all(isinstance(x, bool) for x in hidden["columns"]["torque"])
    shown = run("show")
    if shown["numpy"]:
        assert shown["kinds"] == ["ndarray"]
        assert shown["columns"] == hidden["columns"] and shown["reads"] == hidden["reads"]
