// A drive_link over the simulator's virtual drive, in virtual time, for the session's tests: a
// cycle every `cycle` us writes the cyclic outputs and the control word into the drive, steps it
// and reads the inputs back; a transfer ends at the next poll (never inside upload()), typed by the
// core's object table, with objects of its own beside it and refusals a test sets. It records
// every control word and download, so a test sees what went where and when.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cia402/axis/drive_link.hpp"
#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"

namespace cia402::axes::test {

class sim_link final : public drive_link {
 public:
  explicit sim_link(const profile& p = standard_profile(), bool cyclic_setpoints = true) : drive(p) {
    for (int i = 0; i < 10; ++i) drive.step();  // past power-up (T0, T1)
    inputs = {{object_index::status_word, 0, 16},           {object_index::error_code, 0, 16},
              {object_index::velocity_actual_value, 0, 32}, {object_index::position_actual_value, 0, 32},
              {object_index::modes_of_operation_display, 0, 8}, {object_index::torque_actual_value, 0, 16}};
    outputs = {{object_index::control_word, 0, 16}};
    if (cyclic_setpoints) {
      outputs.push_back({object_index::target_position, 0, 32});
      outputs.push_back({object_index::target_velocity, 0, 32});
      outputs.push_back({object_index::target_torque, 0, 16});
      outputs.push_back({object_index::modes_of_operation, 0, 8});
    }
  }

  mutable sim::virtual_drive drive;  // its view() is not const
  std::vector<cyclic_object> inputs, outputs;
  std::uint32_t cycle = 1000;
  std::uint64_t now = 0;
  std::string failure;                 // non-empty: the link has failed
  std::uint16_t hidden_status_bits = 0;  // bits the status word never shows (remote off)
  /// Objects of the link's own (not the drive's): their bytes, and their size a download must have.
  std::map<std::pair<std::uint16_t, std::uint8_t>, std::vector<std::uint8_t>> own;
  std::map<std::pair<std::uint16_t, std::uint8_t>, unsigned> own_size;
  std::map<std::pair<std::uint16_t, std::uint8_t>, value_format> described;
  std::map<std::pair<std::uint16_t, std::uint8_t>, sdo_abort> refused;  // any transfer of it
  std::vector<std::pair<std::uint64_t, std::uint16_t>> words;          // (time, control word)
  struct download_seen {
    std::uint16_t index;
    std::uint8_t sub;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<download_seen> downloads;
  bool closed = false;

  std::uint32_t poll(std::uint32_t elapsed_us) override {
    now += elapsed_us;
    pending_us_ += elapsed_us;
    if (failure.empty()) {
      while (pending_us_ >= cycle) {
        pending_us_ -= cycle;
        one_cycle();
      }
      if (!transfers_.empty()) {
        auto t = std::move(transfers_.front());
        transfers_.pop_front();
        run(t);
      }
    }
    return cycle - pending_us_;
  }
  link_phase phase() const override { return failure.empty() ? link_phase::running : link_phase::failed; }
  std::string phase_text() const override { return failure; }
  std::string what() const override { return "the simulated drive"; }
  std::string short_name() const override { return "sim"; }
  bool cyclic() const override { return failure.empty(); }
  void start_cyclic() override {}
  std::uint32_t cycle_us() const override { return cycle; }
  bool status_known() const override { return count_ > 0; }
  std::uint16_t status_word() const override { return static_cast<std::uint16_t>(status_ & ~hidden_status_bits); }
  std::uint64_t status_count() const override { return count_; }
  std::optional<std::uint16_t> error_code() const override { return error_code_; }
  void set_control_word(std::uint16_t word) override {
    word_ = word;
    words.emplace_back(now, word);
  }
  const std::vector<cyclic_object>& cyclic_inputs() const override { return inputs; }
  const std::vector<cyclic_object>& cyclic_outputs() const override { return outputs; }
  std::optional<std::int64_t> cyclic_input(std::uint16_t index, std::uint8_t sub) const override {
    if (!carried(inputs, index, sub) || count_ == 0) return std::nullopt;
    if (index == object_index::status_word) return status_word();
    const auto v = sampled_.find(index);
    return v == sampled_.end() ? std::nullopt : std::optional(v->second);
  }
  bool set_cyclic_output(std::uint16_t index, std::uint8_t sub, std::int64_t value) override {
    if (!carried(outputs, index, sub)) return false;
    if (index == object_index::control_word) {
      set_control_word(static_cast<std::uint16_t>(value));
    } else {
      out_values_[index] = value;
    }
    return true;
  }
  bool upload(std::uint16_t index, std::uint8_t sub, transfer_done done) override {
    if (!failure.empty()) return false;
    transfers_.push_back({index, sub, false, {}, std::move(done)});
    return true;
  }
  bool download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes, transfer_done done) override {
    if (!failure.empty()) return false;
    transfers_.push_back({index, sub, true, std::move(bytes), std::move(done)});
    return true;
  }
  std::optional<value_format> describe(std::uint16_t index, std::uint8_t sub) const override {
    const auto d = described.find({index, sub});
    return d == described.end() ? std::nullopt : std::optional(d->second);
  }
  void close() override {
    closed = true;
    report_.done = true;
  }
  const close_report& closing() const override { return report_; }

  /// The link breaks: every transfer queued is cancelled, as a real link's are.
  void fail(const std::string& why) {
    failure = why;
    transfer_result r;
    r.cancelled = true;
    r.error = why;
    auto gone = std::move(transfers_);
    transfers_.clear();
    for (auto& t : gone) {
      if (t.done) t.done(r);
    }
    if (on_event) on_event(link_event::failed, why);
  }

 private:
  struct transfer {
    std::uint16_t index;
    std::uint8_t sub;
    bool download;
    std::vector<std::uint8_t> bytes;
    transfer_done done;
  };

  static bool carried(const std::vector<cyclic_object>& list, std::uint16_t index, std::uint8_t sub) {
    for (const auto& o : list) {
      if (o.index == index && o.sub == sub) return true;
    }
    return false;
  }

  // As an EtherCAT frame does: the inputs it brings back are what the drive had before it took the
  // outputs the frame carries; the drive acts on those in its next step.
  void one_cycle() {
    if (before_cycle) before_cycle();
    status_ = drive.view().outputs().status_word;
    error_code_ = drive.view().outputs().error_code;
    for (const auto& o : inputs) {
      std::int64_t v = 0;
      if (drive.read(o.index, o.sub, v) == sdo_abort::none) sampled_[o.index] = v;
    }
    for (const auto& [index, v] : out_values_) (void)drive.write(index, 0, v);
    if (word_) (void)drive.write(object_index::control_word, 0, *word_);
    drive.step();
    ++count_;
    const std::uint16_t code = drive.view().outputs().error_code;
    if (code != last_code_) {
      last_code_ = code;
      const std::uint8_t bytes[5] = {};
      if (on_emergency) on_emergency(code, drive.view().outputs().error_register, bytes);
    }
  }

  void run(transfer& t) {
    transfer_result r;
    const auto key = std::make_pair(t.index, t.sub);
    if (const auto no = refused.find(key); no != refused.end()) {
      r.abort = no->second;
    } else if (own.count(key) != 0) {
      if (t.download) {
        const auto size = own_size.find(key);
        if (size != own_size.end() && t.bytes.size() != size->second) {
          r.abort = t.bytes.size() > size->second ? sdo_abort::data_type_length_too_high : sdo_abort::data_type_length_too_low;
        } else {
          own[key] = t.bytes;
          downloads.push_back({t.index, t.sub, t.bytes});
          r.ok = true;
        }
      } else {
        r.ok = true;
        r.data = own[key];
      }
    } else if (const object_description* o = find_drive_object(t.index, t.sub)) {
      const std::size_t size = type_size(o->type);
      if (t.download) {
        if (t.bytes.size() != size) {
          r.abort = t.bytes.size() > size ? sdo_abort::data_type_length_too_high : sdo_abort::data_type_length_too_low;
        } else {
          std::uint64_t u = 0;
          for (std::size_t i = 0; i < size; ++i) u |= std::uint64_t{t.bytes[i]} << (8 * i);
          std::int64_t v = static_cast<std::int64_t>(u);
          if (type_is_signed(o->type) && size < 8 && (t.bytes.back() & 0x80)) v = static_cast<std::int64_t>(u | (~std::uint64_t{0} << (8 * size)));
          r.abort = drive.write(t.index, t.sub, v);
          r.ok = r.abort == sdo_abort::none;
          if (r.ok) downloads.push_back({t.index, t.sub, t.bytes});
        }
      } else {
        std::int64_t v = 0;
        r.abort = drive.read(t.index, t.sub, v);
        r.ok = r.abort == sdo_abort::none;
        if (r.ok) {
          for (std::size_t i = 0; i < size; ++i) r.data.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i)));
        }
      }
    } else {
      r.abort = sdo_abort::object_does_not_exist;
    }
    if (t.done) t.done(r);
  }

  std::deque<transfer> transfers_;
  std::map<std::uint16_t, std::int64_t> out_values_;
  std::optional<std::uint16_t> word_;
  std::uint32_t pending_us_ = 0;
  std::uint64_t count_ = 0;
  std::uint16_t last_code_ = 0;
  std::uint16_t status_ = 0;
  std::uint16_t error_code_ = 0;
  std::map<std::uint16_t, std::int64_t> sampled_;
  close_report report_;
};

}  // namespace cia402::axes::test
