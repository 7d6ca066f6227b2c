#include "cia402/compiled.hpp"

namespace cia402 {
namespace {

constexpr std::uint8_t no_word = 0xFF;

// The first control word (bits 0..4) the profile decodes to each command, or no_word.
std::array<std::uint8_t, 8> word_of_command(const profile& p) noexcept {
  std::array<std::uint8_t, 8> words;
  words.fill(no_word);
  for (std::uint8_t bits = 0; bits < 32; ++bits) {
    std::uint8_t& w = words[static_cast<unsigned>(p.decode(bits))];
    if (w == no_word) w = bits;
  }
  return words;
}

bool resting(const profile& p, state s) noexcept {
  const state_activity act = p.info(s).activity;
  return act != state_activity::quick_stop && act != state_activity::fault_reaction;
}

bool same(const drive_outputs& x, const drive_outputs& y) noexcept {
  return x.current == y.current && x.status_word == y.status_word && x.transition == y.transition &&
         x.ramp == y.ramp && x.torque == y.torque && x.brake_released == y.brake_released &&
         x.clear_setpoints == y.clear_setpoints && x.error_code == y.error_code &&
         x.error_register == y.error_register;
}

// A key whose state and command exist, with a control word the profile decodes to its command.
bool usable(const std::array<std::uint8_t, 8>& words, unsigned key) noexcept {
  const unsigned command = (key >> 4) & 7u;
  return (key & 0xFu) < static_cast<unsigned>(state_count) &&
         command < static_cast<unsigned>(command_count) && words[command] != no_word;
}

// Whether offset_of gives every key a slot of its own in the tables: the table is filled key by
// key, and two keys in one slot would leave the first answered by the second's entry.
constexpr bool offsets_are_a_permutation() noexcept {
  bool taken[compiled_profile::entry_count] = {};
  for (unsigned key = 0; key < compiled_profile::entry_count; ++key) {
    const std::size_t at = compiled_profile::offset_of(key);
    const std::size_t slot = at / sizeof(compiled_entry);
    if (at % sizeof(compiled_entry) != 0 || slot >= compiled_profile::entry_count || taken[slot]) {
      return false;
    }
    taken[slot] = true;
  }
  return true;
}
static_assert(offsets_are_a_permutation(), "offset_of must place the 1,024 keys in 1,024 slots");

// Four axis bytes (flags, state, pending row, last transition) as the word the compiled step reads
// and writes.
std::uint32_t axis_word(const std::uint8_t (&bytes)[4]) noexcept {
  std::uint32_t w;
  std::memcpy(&w, bytes, 4);
  return w;
}

// The first 8 bytes of `o`, padding zero: an entry's image of the outputs.
std::uint64_t image_of(const drive_outputs& o) noexcept {
  drive_outputs image;
  std::memset(static_cast<void*>(&image), 0, sizeof image);
  image.current = o.current;
  image.status_word = o.status_word;
  image.transition = o.transition;
  image.ramp = o.ramp;
  image.torque = o.torque;
  image.brake_released = o.brake_released;
  image.clear_setpoints = o.clear_setpoints;
  std::uint64_t bytes;
  std::memcpy(&bytes, &image, 8);
  return bytes;
}

// What a cycle does to the axis flags across probes: a bit every probe ends with the same value as
// `first` is set (or cleared), one that keeps what it was is kept; any other cannot be a table's.
struct flag_rule {
  unsigned same_after = 0x1Fu;
  unsigned kept = 0x1Fu;
  bool holds() const noexcept { return (same_after | kept) == 0x1Fu; }
};

struct probe {
  axis a;
  drive_inputs in;
};

template <typename MakeProbe>
flag_rule flags_across(const profile& p, unsigned count, std::uint8_t first, MakeProbe make) noexcept {
  flag_rule r;
  for (unsigned v = 0; v < count; ++v) {
    probe pr = make(v);
    const std::uint8_t was = pr.a.flags;
    detail::full_step(p, pr.a, pr.in);
    r.same_after &= ~static_cast<unsigned>(pr.a.flags ^ first);
    r.kept &= ~static_cast<unsigned>(pr.a.flags ^ was);
  }
  return r;
}

// The compiled step equals the full step, outputs and axis, on every probe.
template <typename MakeProbe>
bool agrees(const compiled_profile& c, unsigned count, MakeProbe make) noexcept {
  for (unsigned v = 0; v < count; ++v) {
    probe full = make(v);
    probe table = full;
    const drive_outputs want = detail::full_step(c.source(), full.a, full.in);
    const drive_outputs got = step(c, table.a, table.in);
    if (!same(want, got) || std::memcmp(&full.a, &table.a, sizeof(axis)) != 0) return false;
  }
  return true;
}

// The axis flags of a key's bits 8 and 9.
std::uint8_t key_flags(unsigned key) noexcept {
  return static_cast<std::uint8_t>(((key & 0x100u) ? axis_flag::fault_reset_bit : 0u) |
                                   ((key & 0x200u) ? axis_flag::torque_on : 0u));
}

// The facts an ordinary cycle leaves open: an entry holds only where the full step answers the
// same for every one of them.
constexpr unsigned variant_bits = 8;  // halt, standstill, 3 flags, 2 option codes, status bits
constexpr unsigned variant_count = 3u << variant_bits;  // times 0x605A: coasts, ends, holds (S5)

probe make_probe(const profile& p, unsigned key, std::uint8_t word, unsigned v) noexcept {
  probe r{make_axis(p), drive_inputs{}};
  const std::int8_t quick_stop_codes[3] = {0, 1, 5};
  r.a.current = static_cast<state>(key & 0xFu);
  r.a.options[static_cast<int>(option::quick_stop)] = quick_stop_codes[v >> variant_bits];
  r.a.options[static_cast<int>(option::shutdown)] = static_cast<std::int8_t>((v >> 5) & 1u);
  r.a.options[static_cast<int>(option::disable_operation)] = static_cast<std::int8_t>((v >> 6) & 1u);
  r.a.flags = static_cast<std::uint8_t>(key_flags(key) | ((v & 4u) ? axis_flag::entered_by_fault : 0u) |
                                        ((v & 8u) ? axis_flag::fault_latched : 0u) |
                                        ((v & 16u) ? axis_flag::coast_reaction : 0u));
  r.a.error_code = 0x1234;  // shows whether the step clears it
  r.a.last_transition = 9;  // and whether it keeps the last transition
  r.in.control_word =
      static_cast<std::uint16_t>(word | (key & 0x80u) | ((v & 1u) ? 0x100u : 0u));
  r.in.standstill = (v & 2u) != 0;
  r.in.status_bits = (v & 128u) ? 0xFFFFu : 0u;
  return r;
}

}  // namespace

compiled_profile::compiled_profile(const profile& p) noexcept : profile_(&p) {
  // The stop table is empty while the ordinary table is checked: its rare path is the full step.
  stop_block_.fill(no_block);
  slot_of_row_.fill(no_slot);
  has_speed_limit_ = p.speed_limit_rpm > 0;
  speed_offset_ = has_speed_limit_ ? std::int64_t{p.speed_limit_rpm} - 1 : 0;
  speed_span_ = has_speed_limit_ ? static_cast<std::uint64_t>(2 * std::int64_t{p.speed_limit_rpm} - 2) : ~0ull;
  for (unsigned bits = 0; bits < 256; ++bits) {
    const unsigned command_key = (p.command_of_bits[bits & 0x1Fu] << 4) | (bits & 0x80u);
    command_key_[bits] = static_cast<std::uint8_t>(command_key);
    row_offset_[bits] = static_cast<std::uint16_t>(offset_of(command_key));
  }
  const bool has_halt = p.spec(option::halt).exists();
  const std::array<std::uint8_t, 8> words = word_of_command(p);
  compiled_entry fall_back;
  fall_back.keep = axis_word({0, 0, fallback, 0});  // flags, state, pending row, last transition
  fall_back.set = axis_word({0, 0, no_pending_row, 0});
  tables_.entries.fill(fall_back);
  for (unsigned key = 0; key < entry_count; ++key) {
    if (!usable(words, key) || !resting(p, static_cast<state>(key & 0xFu))) continue;
    const std::uint8_t word = words[(key >> 4) & 7u];
    const auto probe_of = [&](unsigned v) { return make_probe(p, key, word, v); };
    // What the full step does with the first probe makes the entry; every probe then checks it.
    probe first = probe_of(0);
    const axis before = first.a;
    const drive_outputs out = detail::full_step(p, first.a, first.in);
    if (stop_running(first.a) || !resting(p, first.a.current)) continue;
    const bool committed = out.transition != no_transition;
    const flag_rule flags = flags_across(p, variant_count, first.a.flags, probe_of);
    if (!flags.holds()) continue;
    const state_info info = p.info(first.a.current);
    const bool running = info.activity == state_activity::run;
    std::uint8_t actions = 0;
    if (committed && first.a.error_code == 0 && before.error_code != 0) actions |= resets_error;
    if (running) actions |= runs;
    if (running && has_halt) actions |= halt_possible;
    compiled_entry e;
    // Bytes 0..3 of the axis: the flags, the state, the pending row (none, and none after: the
    // actions ride in keep's byte, their trace OR-ed away by set's 0xFF), the last transition
    // (kept unless a row fires).
    e.keep = axis_word({static_cast<std::uint8_t>(flags.kept & ~flags.same_after), 0, actions,
                        static_cast<std::uint8_t>(committed ? 0x00 : 0xFF)});
    e.set = axis_word({static_cast<std::uint8_t>(first.a.flags & flags.same_after),
                       static_cast<std::uint8_t>(first.a.current), no_pending_row,
                       static_cast<std::uint8_t>(committed ? out.transition : 0)});
    // The image without the reported status bits (OR-ed in per cycle), halt or ramp.
    drive_outputs image;
    image.current = first.a.current;
    image.status_word = static_cast<std::uint16_t>(info.status_pattern | status_bit::voltage_enabled |
                                                   status_bit::remote);
    image.transition = out.transition;
    image.torque = info.activity != state_activity::idle;
    image.brake_released = image.torque;
    image.clear_setpoints = out.clear_setpoints;
    // The entry stands only if the compiled step with it equals the full step on every probe.
    const std::size_t at = offset_of(key) / sizeof(compiled_entry);
    tables_.entries[at] = e;
    tables_.images[at] = image_of(image);
    if (!agrees(*this, variant_count, probe_of)) tables_.entries[at] = fall_back;
  }
  compile_stops();
}

namespace {

constexpr unsigned stop_variant_count = 8;  // 2 flags, status bits
constexpr unsigned reporting_variant = 4;   // every reported status bit set

// A probe of the stop table: an axis with the profile's default option codes.
probe make_stop_probe(const profile& p, unsigned key, std::uint8_t word, unsigned sub,
                      std::uint8_t pending, std::int8_t code, unsigned v) noexcept {
  probe r{make_axis(p), drive_inputs{}};
  r.a.current = static_cast<state>(key & 0xFu);
  r.a.flags = static_cast<std::uint8_t>(key_flags(key) |
                                        ((key & 0x400u) ? axis_flag::entered_by_fault : 0u) |
                                        ((v & 1u) ? axis_flag::fault_latched : 0u) |
                                        ((v & 2u) ? axis_flag::coast_reaction : 0u));
  r.a.pending_row = pending;
  r.a.stop_code = code;
  r.a.error_code = 0x1234;  // shows whether the step clears it
  r.a.last_transition = 9;  // and whether it keeps the last transition
  r.in.control_word = static_cast<std::uint16_t>(word | (key & 0x80u));
  r.in.standstill = (sub & 1u) != 0;
  r.in.brake_engaged = (sub & 2u) != 0;
  r.in.status_bits = (v & reporting_variant) ? 0xFFFFu : 0u;
  return r;
}

}  // namespace

void compiled_profile::compile_stops() noexcept {
  const profile& p = *profile_;
  const axis defaults = make_axis(p);
  std::memcpy(default_options_, defaults.options, sizeof default_options_);
  slot_of_row_[no_pending_row] = 0;
  const std::array<std::uint8_t, 8> words = word_of_command(p);

  // The pending rows, the stop code each runs by and the state it runs in, and the stop code each
  // state is entered with: as the full step leaves them, from every key, with the defaults.
  std::uint8_t slot_row[4] = {no_pending_row, no_pending_row, no_pending_row, no_pending_row};
  std::int8_t slot_code[4] = {};
  state slot_state[4] = {};
  unsigned slots = 1;
  std::int8_t entry_code[16] = {};
  for (unsigned from = 0; from < slots; ++from) {  // pending rows found from pending rows too
    for (unsigned key = 0; key < stop_key_count; ++key) {
      if (!usable(words, key) || (from != 0 && static_cast<state>(key & 0xFu) != slot_state[from])) continue;
      for (unsigned sub = 0; sub < 4; ++sub) {
        probe pr = make_stop_probe(p, key, words[(key >> 4) & 7u], sub, slot_row[from],
                                        slot_code[from], 0);
        const drive_outputs out = detail::full_step(p, pr.a, pr.in);
        if (pr.a.pending_row != no_pending_row && slot_of_row_[pr.a.pending_row] == no_slot &&
            slots < 4) {
          slot_row[slots] = pr.a.pending_row;
          slot_code[slots] = pr.a.stop_code;
          slot_state[slots] = pr.a.current;
          slot_of_row_[pr.a.pending_row] = static_cast<std::uint8_t>(slots++);
        }
        if (out.transition != no_transition && pr.a.pending_row == no_pending_row) {
          entry_code[static_cast<unsigned>(pr.a.current)] = pr.a.stop_code;
        }
      }
    }
  }

  std::size_t next_block = 0;
  for (unsigned key = 0; key < stop_key_count; ++key) {
    if (!usable(words, key)) continue;
    const state s = static_cast<state>(key & 0xFu);
    if (p.info(s).activity == state_activity::idle) continue;  // no stop runs without torque
    if (next_block + stop_block > stop_capacity) {
      stops_complete_ = false;
      continue;
    }
    stop_block_[key] = static_cast<std::uint16_t>(next_block);
    for (unsigned sub = 0; sub < stop_block; ++sub) {
      stop_entry& e = stops_[next_block + sub];
      const unsigned slot = sub >> 2;
      if (slot >= slots || (slot != 0 && slot_state[slot] != s)) continue;
      const std::int8_t code = slot != 0 ? slot_code[slot] : entry_code[static_cast<unsigned>(s)];
      const std::uint8_t word = words[(key >> 4) & 7u];
      const auto probe_of = [&](unsigned v) {
        return make_stop_probe(p, key, word, sub, slot_row[slot], code, v);
      };
      probe first = probe_of(0);
      const axis before = first.a;
      const drive_outputs out = detail::full_step(p, first.a, first.in);
      const bool committed = out.transition != no_transition;
      const flag_rule flags = flags_across(p, stop_variant_count, first.a.flags, probe_of);
      if (!flags.holds()) continue;
      // Whether the motion side's target reached shows: with every reported bit set.
      probe reporting = probe_of(reporting_variant);
      const drive_outputs all = detail::full_step(p, reporting.a, reporting.in);
      stop_entry made;
      made.keep = axis_word({static_cast<std::uint8_t>(flags.kept & ~flags.same_after), 0, 0,
                             static_cast<std::uint8_t>(committed ? 0x00 : 0xFF)});
      made.set = axis_word({static_cast<std::uint8_t>(first.a.flags & flags.same_after),
                            static_cast<std::uint8_t>(first.a.current), first.a.pending_row,
                            static_cast<std::uint8_t>(committed ? out.transition : 0)});
      made.image = image_of(out);
      made.code_before = code;
      made.code_after = first.a.stop_code;
      made.actions = 0;
      if (committed && first.a.error_code == 0 && before.error_code != 0) made.actions |= resets_error;
      if (all.status_word & ~out.status_word & status_bit::target_reached) made.actions |= runs;
      // The entry stands only if the compiled step with it equals the full step on every probe.
      e = made;
      if (!agrees(*this, stop_variant_count, probe_of)) e = stop_entry{};
    }
    // A block that answers nothing is given back: the keys with a stop to answer fit the table.
    bool answers = false;
    for (unsigned sub = 0; sub < stop_block; ++sub) answers |= (stops_[next_block + sub].actions & fallback) == 0;
    if (answers) {
      next_block += stop_block;
    } else {
      stop_block_[key] = no_block;
      for (unsigned sub = 0; sub < stop_block; ++sub) stops_[next_block + sub] = stop_entry{};
    }
  }
}

std::size_t compiled_profile::stops_covered() const noexcept {
  std::size_t n = 0;
  for (std::size_t key = 0; key < stop_key_count; ++key) {
    if (stop_block_[key] == no_block) continue;
    for (std::size_t i = 0; i < stop_block; ++i) n += (stops_[stop_block_[key] + i].actions & fallback) == 0;
  }
  return n;
}

std::size_t compiled_profile::covered() const noexcept {
  std::size_t n = 0;
  for (const compiled_entry& e : tables_.entries) n += ((e.keep >> detail::byte_shift<4>(2)) & fallback) == 0;
  return n;
}

}  // namespace cia402
