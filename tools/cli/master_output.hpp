// What `cia402 master` prints: one line an event or a step's result, in words ("node 1: reached
// OPERATION_ENABLED") or with --json as one JSON object that names the drive first
// ({"node":1,"event":"reached",...}; on EtherCAT "slave" instead of "node"). Failures go to standard
// error in words, and with --json also as a "failed" line. docs/master.md lists every shape.
#pragma once

#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>

#include "cia402/axis/session.hpp"
#include "cli/master_steps.hpp"

namespace cia402::cli {

/// How a line names a drive: {"node", 1} or {"slave", 0}.
struct drive_tag {
  std::string key;
  int number = 0;
  std::string prose() const { return key + " " + std::to_string(number); }
};

class master_output {
 public:
  master_output(std::ostream& out, std::ostream& err, bool json) : out_(&out), err_(&err), json_(json) {}

  /// A line about one drive.
  void drive(const drive_tag& who, const nlohmann::ordered_json& fields, const std::string& prose);
  /// A line about the line or the run as a whole.
  void line(const nlohmann::ordered_json& fields, const std::string& prose);
  /// A step that failed: in words on standard error, and with --json a "failed" line.
  void failure(const drive_tag& who, const std::string& step, const std::string& why);
  /// A failure that is no drive's (a bus that cannot be opened).
  void error(const std::string& why);
  bool json_lines() const noexcept { return json_; }

  /// The step's result, as its verb prints it.
  void result(const drive_tag& who, const master_step& step, const axes::result& r);
  /// What an operation reports on its way; `stream_words` says how a stream goes on this bus.
  void progress(const drive_tag& who, axes::progress_kind kind, const axes::result& r, const std::string& stream_words,
                std::uint32_t cycle_us);
  /// Events of a session: a state the drive shows, an emergency, the link, the cyclic exchange.
  void state(const drive_tag& who, state s, std::uint16_t status_word, std::uint16_t error_code);
  void emergency(const drive_tag& who, std::uint16_t code, std::uint8_t reg, bool reg_known);
  void started(const drive_tag& who, const axes::drive_link& link);
  void closed(const drive_tag& who, const axes::close_report& report);

 private:
  std::ostream* out_;
  std::ostream* err_;
  bool json_;
};

}  // namespace cia402::cli
