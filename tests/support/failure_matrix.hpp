// The failure matrix's vocabulary (S20), shared by its runs over the fake link (tests/axis), the CAN
// link (tests/canopen) and the EtherCAT link (tests/ethercat): the motion commands, the failures
// injected, what an error may name for each, and how a command is started on a session.
#pragma once

#include <string>
#include <vector>

#include "cia402/axis/session.hpp"

namespace cia402::failure_matrix {

enum class kind { move, velocity, jog, csp, home, torque };
enum class failure { cancel, link_lost, fault, sto, dc_link_lost, refused_sdo };
inline constexpr kind kinds[] = {kind::move, kind::velocity, kind::jog, kind::csp, kind::home, kind::torque};
inline constexpr failure failures[] = {failure::cancel, failure::link_lost, failure::fault,
                                       failure::sto,    failure::dc_link_lost, failure::refused_sdo};

inline const char* name(kind k) {
  switch (k) {
    case kind::move: return "move";
    case kind::velocity: return "velocity";
    case kind::jog: return "jog";
    case kind::csp: return "csp stream";
    case kind::home: return "home";
    case kind::torque: return "torque";
  }
  return "?";
}

inline const char* name(failure f) {
  switch (f) {
    case failure::cancel: return "cancel";
    case failure::link_lost: return "link lost";
    case failure::fault: return "fault";
    case failure::sto: return "STO";
    case failure::dc_link_lost: return "DC link lost";
    case failure::refused_sdo: return "refused SDO";
  }
  return "?";
}

// What the error may name for each failure, once the request had not ended before it: the failure
// itself, or what the drive showed of it (STO before the enable is a transition that does not come,
// with the warning bit; a DC link gone before it is a refusal). A lost link is said in each bus's
// words: `link_lost`.
inline std::vector<std::string> cause_words(failure f, const std::string& link_lost) {
  switch (f) {
    case failure::cancel: return {"the client gave up"};
    case failure::link_lost: return {link_lost};
    case failure::fault: return {"error code 0x7121"};
    case failure::sto: return {"FAULT", "safe torque off"};
    case failure::dc_link_lost: return {"FAULT", "no DC link"};
    case failure::refused_sdo: return {"SDO abort 0x06090030"};
  }
  return {};
}

inline bool names_one(const std::string& error, const std::vector<std::string>& words) {
  for (const std::string& w : words) {
    if (error.find(w) != std::string::npos) return true;
  }
  return false;
}

// The same command of each kind on every bus.
inline void start(axes::session& s, kind k, axes::completion done) {
  switch (k) {
    case kind::move: s.move({2'000'000, false, 3000u}, std::move(done)); break;
    case kind::velocity: s.velocity(3000, std::move(done)); break;
    case kind::jog: s.jog(1500, 10'000'000, std::move(done)); break;
    case kind::csp: s.csp_stream(2'000'000, 1200, std::move(done)); break;
    case kind::home: s.home({std::int8_t{17}, 0}, std::move(done)); break;
    case kind::torque: s.torque(100, std::move(done)); break;
  }
}

}  // namespace cia402::failure_matrix
