// The axis session's link to a CiA 402 drive on an EtherCAT line (axis/drive_link.hpp), over our
// EtherCAT master (ethercat/master/ecat_master.hpp).
//
// One `ecat_line` per line: the master, brought to OP once, cycled at its period by whichever drive
// link polls first when a cycle is due (each drive's `before_cycle` first, so a stream's set-point
// goes in the cycle it was made for). One `ecat_link` per drive on it:
// - the cyclic data is the mapping the master learnt (0x1C12/0x1C13 over CoE, else the SII's
//   defaults): the control word and every other output object it maps (0x6060, 0x607A, 0x60FF,
//   0x6071, ...) go in the LRW, so a write to one is not undone by the next cycle; the inputs
//   (0x6041, 0x6064, 0x606C, 0x6077, 0x6061, 0x603F, ...) come from it;
// - an object transfer (CoE SDO) runs between two cycles, one at a time, the process data flowing
//   while it waits;
// - describe(): the types of ETG.1000.6's CoE objects (0x1000, 0x1001, 0x1008..0x100A, 0x1018, the
//   PDO mapping and assignment objects, 0x1C00), and for the project's virtual drive (its SII
//   name) its manufacturer objects;
// - close(): nothing in a drive's dictionary was changed (the mapping is read, not written). A drive
//   the run left enabled (SWITCHED ON, OPERATION ENABLED, QUICK STOP ACTIVE) is first brought down
//   to SWITCH ON DISABLED in the process data (Disable voltage, after a quick stop while it still
//   turns; the link's control word from then on), within 3 s: leaving OP is then no lost
//   connection for its 0x6007 (1 by default: a fault), and the next run finds it without a fault.
//   Once every drive's link is closed the line leaves OP for PRE-OP at once, rather than by the
//   sync managers' watchdog; the report says how each drive was left.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/profile.hpp"

namespace cia402::ethercat {

class ecat_link;

class ecat_line {
 public:
  /// `link` and `p` must outlive the line; `name` is how what() names it ("ecm").
  ecat_line(master_link& link, const profile& p, std::uint32_t cycle_us, std::string name);

  /// Scan, SII, mailbox, the mapping, SAFE-OP and OP (blocking, as the master's bring-up is):
  /// false with error().
  bool scan();
  bool bring_to_operational();
  const std::string& error() const noexcept { return master_.error(); }
  ecat_master& master() noexcept { return master_; }
  const ecat_master& master() const noexcept { return master_; }
  const std::string& name() const noexcept { return name_; }
  bool operational() const noexcept { return up_; }

  /// A cycle when one is due by the line's clock (each drive's before_cycle first); the
  /// microseconds until the next.
  std::uint32_t service();
  /// Cycles run since OP, and whether the line answers.
  std::uint64_t cycles() const noexcept { return master_.cycles(); }
  bool failed() const noexcept { return !failure_.empty(); }
  const std::string& failure() const noexcept { return failure_; }
  /// A line that stopped answering is scanned and brought to OP again this long after it failed,
  /// and again each retry_us until it answers; its drives' links then run afresh (their sessions
  /// read the drives again). 0 (the default): a failed line stays failed.
  void set_retry_us(std::uint32_t retry_us) noexcept { retry_us_ = retry_us; }

 private:
  friend class ecat_link;
  void attach(ecat_link* l);
  void detach_closed();

  master_link* link_;
  const profile* profile_;
  ecat_master master_;
  std::string name_;
  bool up_ = false;
  bool left_op_ = false;
  std::uint64_t next_cycle_us_ = 0;
  int lost_in_a_row_ = 0;
  std::string failure_;
  std::uint32_t retry_us_ = 0;
  std::uint64_t retry_at_us_ = 0;
  std::vector<ecat_link*> drives_;
};

class ecat_link final : public axes::link_base {
 public:
  /// Drive `position` on `line` (which must outlive the link and be in OP for it to run).
  ecat_link(ecat_line& line, std::size_t position);
  ~ecat_link() override;

  std::uint32_t poll(std::uint32_t elapsed_us) override;
  axes::link_phase phase() const override;
  std::string phase_text() const override;
  std::string what() const override;
  std::string short_name() const override;

  bool cyclic() const override { return phase() == axes::link_phase::running; }
  void start_cyclic() override {}
  std::uint32_t cycle_us() const override { return line_->master().cycle_us(); }
  bool status_known() const override { return cyclic() && status_count_ > 0; }
  std::uint16_t status_word() const override;
  std::optional<std::uint16_t> error_code() const override;
  void set_control_word(std::uint16_t word) override;

  std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const override;
  bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) override;

  std::optional<axes::value_format> describe(std::uint16_t index, std::uint8_t sub) const override;

  void close() override;

  std::size_t position() const noexcept { return position_; }

 private:
  friend class ecat_line;
  using transfer = axes::pending_transfer;
  const ecat_slave& slave() const { return line_->master().slaves()[position_]; }
  void after_cycle(bool ok);
  void fail(std::string why);
  void restart();  // the line is back in OP: the link runs afresh
  bool queue_transfer(transfer t) override;
  void run_one_transfer();
  void step_stop();     // close(): an enabled drive on its way to SWITCH ON DISABLED, each cycle
  void finish_close();

  ecat_line* line_;
  std::size_t position_;
  bool started_ = false;
  std::string failure_;
  std::size_t emergencies_seen_ = 0;
  std::deque<transfer> transfers_;
  bool closed_ = false;
  bool stopping_ = false;  // closing: the drive first brought down to SWITCH ON DISABLED
  state stop_from_ = state::start;
  std::uint64_t stop_started_us_ = 0;
};

}  // namespace cia402::ethercat
