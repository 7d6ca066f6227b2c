// The CoE slave's process data: each assigned PDO entry bound to its dictionary slot on the way to
// SAFE-OP (padding to nothing), then every cycle a copy of bits between those slots and the sync
// managers' buffers (pdo_maps.hpp, at any bit offset: a gap or a BOOLEAN dummy may leave one), with
// no lookup and no allocation (SOES fills its sync manager maps the same way): outputs in before the
// device's step, inputs out after it (coe_slave::step).
#include <array>
#include <span>

#include "cia402/ethercat/slave/coe_slave.hpp"

namespace cia402::ethercat {
namespace {

constexpr int sm_outputs = 2;
constexpr int sm_inputs = 3;

}  // namespace

unsigned coe_slave::assigned_bits(std::uint16_t assignment) const noexcept {
  unsigned bits = 0;
  const std::int64_t pdos = od_.number(assignment, 0);
  for (std::int64_t i = 1; i <= pdos; ++i) {
    const auto pdo = static_cast<std::uint16_t>(od_.number(assignment, static_cast<std::uint8_t>(i)));
    const std::int64_t entries = od_.number(pdo, 0);
    for (std::int64_t k = 1; k <= entries; ++k) bits += static_cast<std::uint8_t>(od_.number(pdo, static_cast<std::uint8_t>(k)));
  }
  return bits;
}

std::uint16_t coe_slave::output_bytes() const noexcept {
  return static_cast<std::uint16_t>((assigned_bits(0x1C12) + 7) / 8);
}

std::uint16_t coe_slave::input_bytes() const noexcept {
  return static_cast<std::uint16_t>((assigned_bits(0x1C13) + 7) / 8);
}

bool coe_slave::bind(std::uint16_t assignment, std::vector<bound_entry>& out, unsigned& bits) {
  out.clear();
  bits = 0;
  const std::int64_t pdos = od_.number(assignment, 0);
  for (std::int64_t i = 1; i <= pdos; ++i) {
    const auto pdo = static_cast<std::uint16_t>(od_.number(assignment, static_cast<std::uint8_t>(i)));
    const std::int64_t entries = od_.number(pdo, 0);
    for (std::int64_t k = 1; k <= entries; ++k) {
      const auto m = static_cast<std::uint32_t>(od_.number(pdo, static_cast<std::uint8_t>(k)));
      // Padding binds nothing: its bits are skipped in the outputs and stay zeros in the inputs.
      if (is_pdo_padding(static_cast<std::uint16_t>(m >> 16), pdo_padding::dummies_and_gaps)) {
        const unsigned padding = pdo_padding_bits(pdo_mapping_entry::of_word(m), pdo_padding::dummies_and_gaps);
        if (padding == 0) return false;
        bits += padding;
        continue;
      }
      sdo_abort ignored = sdo_abort::none;
      dictionary::object_dictionary::slot* s = od_.find(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8), ignored);
      const auto length = static_cast<std::uint8_t>(m);
      // An entry cleared after its count was written names nothing: the mapping cannot run.
      if (s == nullptr || length == 0 || length > 64 || length % 8 != 0 || bits > 8u * max_process_data) return false;
      out.push_back({s, static_cast<std::uint16_t>(bits), length, type_is_signed(s->entry->type)});
      bits += length;
    }
  }
  return bits <= 8u * max_process_data;
}

void coe_slave::outputs_in() {
  if (state_ != al_state::safe_operational && state_ != al_state::operational) return;
  // Whole buffers through the sync managers checked on the way to SAFE-OP, whose lengths hold the
  // bound entries: the application reaches process RAM only, in the buffer the controller gives it.
  std::array<std::uint8_t, max_process_data> buffer{};
  const bool outputs_arrived = esc_.take_sync_manager_event(sm_outputs);
  const bool sync0 = esc_.take_sync0_event();
  if (dc_sync0_ && sync0) pulse_seen_ = true;
  if (op_waits_for_pulse_ && pulse_seen_) {
    op_waits_for_pulse_ = false;
    enter(al_state::operational);  // and this pulse's outputs are applied below
  }
  // Free run and SM-synchronous: outputs when they arrive. DC SYNC0: the newest on each pulse.
  bool take_outputs = outputs_arrived;
  if (dc_sync0_) {
    outputs_waiting_ = outputs_waiting_ || outputs_arrived;
    take_outputs = sync0;
    if (sync0 && state_ == al_state::operational && !outputs_waiting_) {
      const auto missed = od_.number(sync_parameter::outputs, sync_parameter::sync_error_count);
      if (missed < 0xFFFF) od_.set_number(sync_parameter::outputs, sync_parameter::sync_error_count, missed + 1);
    }
    if (sync0) outputs_waiting_ = false;
  }
  // In SAFE-OP the events are taken (so a pulse or a buffer of then is not applied later) but the
  // outputs stay unapplied.
  const std::size_t out_bytes = outputs_checked_.enabled ? outputs_checked_.length : 0;
  if (state_ == al_state::operational && take_outputs && out_bytes <= buffer.size() &&
      output_bits_ <= 8 * out_bytes && esc_.read_buffer(sm_outputs, std::span(buffer.data(), out_bytes))) {
    for (const bound_entry& e : outputs_) {
      const std::uint64_t raw = pdo_get_bits(buffer.data(), out_bytes, e.bit_offset, e.bits);
      // Signed objects come sign-extended, as the dictionary takes them.
      (void)write(*e.slot, e.is_signed ? pdo_sign_extended(raw, e.bits) : static_cast<std::int64_t>(raw));
    }
  }
}

void coe_slave::inputs_out() {
  // Every cycle in SAFE-OP and OP, so the master always reads the present values.
  if (state_ != al_state::safe_operational && state_ != al_state::operational) return;
  std::array<std::uint8_t, max_process_data> buffer{};
  const std::size_t in_bytes = inputs_checked_.enabled ? inputs_checked_.length : 0;
  if (in_bytes == 0 || in_bytes > buffer.size() || input_bits_ > 8 * in_bytes) return;
  for (const bound_entry& e : inputs_) {
    std::int64_t value = 0;
    (void)read(*e.slot, value);
    pdo_put_bits(buffer.data(), in_bytes, e.bit_offset, e.bits, static_cast<std::uint64_t>(value));
  }
  (void)esc_.write_buffer(sm_inputs, std::span<const std::uint8_t>(buffer.data(), in_bytes));
}

}  // namespace cia402::ethercat
