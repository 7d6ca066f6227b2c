// The cycles of a running or starting stop, compiled from the rows: what a pending row's stop does
// under each key (it goes on, completes, or a row that interrupts stops takes over, S7), the quick
// stop's start (T11) and the cycles of QUICK STOP ACTIVE, for an axis with the profile's default
// 0x605A. The rows stay the one source of truth: each entry is their first match on facts the key
// fixes, and a key whose outcome a fact it leaves open could change is `none` (the full step). The
// model check (tests/core/model_check.hpp) holds the step with them equal to the full step.
#pragma once

#include <cstdint>

namespace cia402::detail {

/// The facts 0x605A's value raises (S5): 1..4 end QUICK STOP ACTIVE by themselves, 5..8 stay.
constexpr std::uint32_t quick_stop_facts(std::int8_t code) noexcept {
  const unsigned qs = static_cast<std::uint8_t>(code);
  return qs - 1u < 4u   ? static_cast<std::uint32_t>(fact::quick_stop_ends)
         : qs - 5u < 4u ? static_cast<std::uint32_t>(fact::quick_stop_stays)
                        : 0u;
}

/// The ramp of a stop code (stop_ramp's values): 1/5 slow-down, 2/6 quick-stop, 3/7 current limit,
/// 4/8 voltage limit, 0 and below coast (0x605A, 0x605E).
constexpr unsigned ramp_of_code(int code) noexcept {
  return code <= 0 ? 5u : static_cast<unsigned>(((code - 1) & 3) + 1);
}

static_assert(ordinary_tables::row_capacity == max_rows, "a row entry for every row");

namespace stop_compile {

constexpr std::uint32_t bit(fact f) noexcept { return static_cast<std::uint32_t>(f); }

// The first row leaving s whose facts hold in f (the full step's first_row), or -1.
constexpr int first_row_on(const profile& p, int s, std::uint32_t f) noexcept {
  for (std::size_t r = 0; r < p.row_count && r < max_rows; ++r) {
    if (((p.rows_from[s] >> r) & 1u) == 0) continue;
    const std::uint32_t any = p.fact_sets[p.rows[r].any], all = p.fact_sets[p.rows[r].all],
                        none = p.fact_sets[p.rows[r].none];
    if ((any & f) && (all & f) == all && !(none & f)) return static_cast<int>(r);
  }
  return -1;
}

// The outputs' first 8 bytes of a state at rest after transition `number` (no_transition: none),
// QUICK STOP ACTIVE by the default 0x605A.
constexpr std::uint64_t image_of(const profile& p, unsigned s, unsigned number, bool clear) noexcept {
  const state_activity act = p.states[s].activity;
  const unsigned ramp =
      act == state_activity::quick_stop ? ramp_of_code(p.options[static_cast<int>(option::quick_stop)].default_value) : 0u;
  const bool torque = act != state_activity::idle && ramp != 5u;
  return (std::uint64_t{s} << byte_shift<8>(0)) | (std::uint64_t{clear} << byte_shift<8>(1)) |
         (std::uint64_t{p.states[s].status_pattern | 0x0210u} << status_shift) |
         (std::uint64_t{number} << byte_shift<8>(4)) | (std::uint64_t{ramp} << byte_shift<8>(5)) |
         (std::uint64_t{torque} << byte_shift<8>(6)) | (std::uint64_t{torque} << byte_shift<8>(7));
}

constexpr bool torque_in(const profile& p, unsigned s) noexcept {
  return (image_of(p, s, 0, false) >> byte_shift<8>(6) & 1u) != 0;
}

// Whether row r (or none, -1) fires in a way an entry can hold: into a state at rest or QUICK STOP
// ACTIVE (`into_quick_stop`), at once (no stop that torque would run first), and without a fault
// reset among its reasons (commit_row then clears the error code, which the entry leaves).
constexpr bool holdable(const profile& p, int r, std::uint32_t f, bool into_quick_stop) noexcept {
  if (r < 0) return true;
  const stored_row& row = p.rows[r];
  if (static_cast<unsigned>(row.to) >= static_cast<unsigned>(state_count)) return false;
  const state_activity to = p.states[static_cast<int>(row.to)].activity;
  return row.stop == row_stop::immediate && !(p.fact_sets[row.any] & f & bit(fact::fault_reset)) &&
         to != state_activity::fault_reaction && ((to == state_activity::quick_stop) == into_quick_stop);
}

// An entry's axis words and image where row r fires (-1: none, the axis stays in s): the axis's
// first four bytes after are (before & keep) | set. The actions mark it for the rare path.
constexpr void put_entry(const profile& p, ordinary_tables& t, std::size_t at, unsigned s, int r, bool bit7) noexcept {
  const bool fires = r >= 0;
  const unsigned to = fires ? static_cast<unsigned>(p.rows[r].to) : s;
  const unsigned actions = ordinary_action::full |
                           (p.states[to].activity == state_activity::run ? ordinary_action::runs : 0u) |
                           (p.speed_limit_rpm > 0 ? ordinary_action::speed_limit : 0u);
  const unsigned kept = 0xFFu & ~static_cast<unsigned>(axis_flag::torque_on | axis_flag::fault_reset_bit) &
                        (fires ? ~static_cast<unsigned>(axis_flag::entered_by_fault) : 0xFFu);
  const unsigned set = (torque_in(p, to) ? unsigned{axis_flag::torque_on} : 0u) |
                       (bit7 ? unsigned{axis_flag::fault_reset_bit} : 0u);
  t.axis_words[at / 4] = (kept << byte_shift<4>(0)) | (actions << byte_shift<4>(2)) |
                         ((fires ? 0u : 0xFFu) << byte_shift<4>(3));
  t.axis_words[at / 4 + 1] = (set << byte_shift<4>(0)) | (to << byte_shift<4>(1)) | (0xFFu << byte_shift<4>(2)) |
                             ((fires ? unsigned{p.rows[r].number} : 0u) << byte_shift<4>(3));
  t.images[at / 8] = image_of(p, to, fires ? p.rows[r].number : no_transition,
                              fires && (p.rows[r].flags & row_flag::clears_setpoints) != 0);
}

// Each row's commit (as put_entry's, without bit 7's flag) and its stop as it runs.
constexpr void compile_rows(const profile& p, ordinary_tables& t) noexcept {
  for (std::size_t i = 0; i < p.row_count && i < max_rows; ++i) {
    const stored_row& r = p.rows[i];
    ordinary_tables::row_entry e{};
    const unsigned to = static_cast<unsigned>(r.to);
    if (to < static_cast<unsigned>(state_count) && !(p.fact_sets[r.any] & bit(fact::fault_reset)) &&
        p.states[to].activity != state_activity::quick_stop &&
        p.states[to].activity != state_activity::fault_reaction) {
      e.actions = static_cast<std::uint8_t>(row_action::commits |
                                            (p.states[to].activity == state_activity::run ? row_action::runs : 0u));
      e.keep = 0xFFu & ~static_cast<unsigned>(axis_flag::torque_on | axis_flag::fault_reset_bit |
                                              axis_flag::entered_by_fault);
      e.set = ((torque_in(p, to) ? unsigned{axis_flag::torque_on} : 0u) << byte_shift<4>(0)) |
              (to << byte_shift<4>(1)) | (0xFFu << byte_shift<4>(2)) | (unsigned{r.number} << byte_shift<4>(3));
      e.image = image_of(p, to, r.number, (r.flags & row_flag::clears_setpoints) != 0);
      // Its stop: from one state, as compile_stop_start's image of it (S7, S12).
      const unsigned from = r.from();
      const unsigned stop = stop_nibble(r.stop);
      if ((stop & stop_bits::ramp) != 0 && from != 0 && (from & (from - 1u)) == 0) {
        unsigned s = 0;
        while (((from >> s) & 1u) == 0) ++s;
        const bool live = (stop & stop_bits::ramp) == stop_bits::halt_ramp_live;
        e.actions = static_cast<std::uint8_t>(
            e.actions | row_action::stop_runs | (live ? row_action::halt_ramp : 0u) |
            ((stop & stop_bits::if_code_is_1) ? row_action::stop_reads_code : 0u) |
            (p.states[to].activity == state_activity::idle ? row_action::stop_ends_torque : 0u));
        e.stop_state = static_cast<std::uint8_t>(s);
        e.stop_image = (std::uint64_t{s} << byte_shift<8>(0)) |
                       (std::uint64_t{p.states[s].status_pattern | 0x0210u} << status_shift) |
                       (std::uint64_t{no_transition} << byte_shift<8>(4)) |
                       (std::uint64_t{live ? 0u : stop & stop_bits::ramp} << byte_shift<8>(5)) |
                       (std::uint64_t{1} << byte_shift<8>(6)) | (std::uint64_t{1} << byte_shift<8>(7));
      }
    }
    t.row_entries[i] = e;
  }
}

}  // namespace stop_compile

constexpr void compile_stop_entries(const profile& p, ordinary_tables& t) noexcept {
  using namespace stop_compile;
  compile_rows(p, t);
  const std::int8_t qs_code = p.options[static_cast<int>(option::quick_stop)].default_value;
  const unsigned qs_flags =
      (ramp_of_code(qs_code) == 5u ? stop_flag::quick_stop_coasts : 0u) |
      (qs_code >= 1 && qs_code <= 4 ? stop_flag::quick_stop_ends_torque : 0u) |
      (qs_code >= 5 && qs_code <= 8 ? stop_flag::quick_stop_stays : 0u) |
      (p.options[static_cast<int>(option::halt)].exists() ? stop_flag::has_halt : 0u);
  for (unsigned key = 0; key < ordinary_tables::entry_count; ++key) {
    const std::size_t at = ordinary_tables::offset_of(key);
    t.stop_words[at / 8] = stop_kind::none;
    const unsigned s = key & 0xFu, c = (key >> 4) & 7u;
    if (s >= static_cast<unsigned>(state_count) || c >= static_cast<unsigned>(command_count)) continue;
    const bool bit7 = ((key >> 7) & 1u) != 0, edge = bit7 && ((key >> 8) & 1u) == 0,
               torque_before = ((key >> 9) & 1u) != 0;
    // The facts the key fixes, with the default 0x605A, entered_by_fault and fault_latched clear,
    // no halt, |speed| below the limit: stop_complete alone is left open.
    const std::uint32_t f = bit(fact::automatic) | bit(fact::dc_link) | bit(fact::below_speed_limit) |
                            static_cast<std::uint32_t>(command_fact(static_cast<command>(c))) |
                            (edge ? bit(fact::fault_reset) : 0u) | quick_stop_facts(qs_code);
    const state_activity act = p.states[s].activity;
    const std::uint8_t code = p.ordinary_entry(static_cast<int>(s), c);
    unsigned kind = stop_kind::none, flags = qs_flags, fired = 0, completes = 0;
    if (act == state_activity::quick_stop) {
      const bool coasts = (qs_flags & stop_flag::quick_stop_coasts) != 0;
      const int open = first_row_on(p, static_cast<int>(s), coasts ? f | bit(fact::stop_complete) : f);
      const int done = first_row_on(p, static_cast<int>(s), f | bit(fact::stop_complete));
      if (!holdable(p, open, f, false) || !holdable(p, done, f | bit(fact::stop_complete), false) ||
          (open >= 0 && done < 0)) {
        continue;
      }
      kind = stop_kind::in_quick_stop;
      flags |= open < 0 ? stop_flag::lands_in_quick_stop : 0u;
      fired = static_cast<unsigned>(open + 1);
      completes = done != open ? static_cast<unsigned>(done + 1) : 0u;
      put_entry(p, t, at, s, open, bit7);
    } else if (act == state_activity::fault_reaction) {
      continue;
    } else if (code == ordinary::full) {
      // A row into QUICK STOP ACTIVE, at once, whatever the stop's completion.
      const int r = first_row_on(p, static_cast<int>(s), f);
      if (r < 0 || r != first_row_on(p, static_cast<int>(s), f | bit(fact::stop_complete)) ||
          !holdable(p, r, f, true)) {
        continue;
      }
      kind = stop_kind::enters_quick_stop;
      flags |= stop_flag::lands_in_quick_stop |
               ((p.rows[r].flags & row_flag::interrupts_stop) ? stop_flag::interrupts : 0u);
      fired = static_cast<unsigned>(r + 1);
      put_entry(p, t, at, s, r, bit7);
    } else if (edge && (code & ordinary::reset_reads) != 0) {
      continue;
    } else {
      kind = torque_before && (code & ordinary::stops) ? stop_kind::stop_start : stop_kind::ordinary;
      fired = code & ordinary::row;
      flags = (qs_flags & stop_flag::has_halt) |
              (fired != 0 && (p.rows[fired - 1].flags & row_flag::interrupts_stop) ? stop_flag::interrupts : 0u);
    }
    t.stop_words[at / 8] = kind | (flags << 8) | (fired << 16) | (completes << 24);
  }
}

}  // namespace cia402::detail
