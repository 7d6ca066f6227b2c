// The extension module cia402._cia402: the core, profiles and the replay interface at the top, the
// simulator in its submodule `sim`. The package's Python files (cia402/__init__.py, sim.py) re-export
// them; a later area (CANopen's virtual bus, the EtherCAT chain, the axis session) binds itself in a
// submodule of its own here.
#include "canopen_bus.hpp"

#ifndef CIA402_VERSION
#error "CIA402_VERSION is set by src/python/CMakeLists.txt from the project's version"
#endif

PYBIND11_MODULE(_cia402, m) {
  using namespace cia402::python;
  m.doc() = "The C++ core of the cia402 package (import cia402, not this).";
  m.attr("__version__") = CIA402_VERSION;
  bind_errors(m);
  bind_profiles(m);
  bind_drive(m);
  bind_replay(m);
  py::module_ sim = m.def_submodule("sim", "Virtual drives on virtual time: machines, traces, scenarios.");
  bind_sim(sim);
  bind_sim_traces(sim);
  py::module_ canopen = m.def_submodule("canopen", "The virtual CAN bus with its drives in process.");
  bind_canopen(canopen);
  py::module_ ethercat = m.def_submodule("ethercat", "A chain of virtual EtherCAT drives and the master over it.");
  bind_ethercat(ethercat, canopen);
}
