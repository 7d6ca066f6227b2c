// A profile is one drive's variant of the state machine, as data: the control-word decoder, the
// transition table (one row per transition the seed prints, T0..T17), what each state does, and
// which option-code values the drive supports. The drive-side machine (drive.hpp), the master side
// and every tool read these tables; nothing else restates them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "cia402/detail/byte_order.hpp"
#include "cia402/detail/ordinary_tables.hpp"
#include "cia402/row_stop.hpp"
#include "cia402/state.hpp"
#include "cia402/words.hpp"

/// 0 leaves the built-in profiles' text for tools (profile::seed, profile::title) out, as "": 436
/// bytes of a firmware's flash for the five, which no drive reads. Names stay.
#ifndef CIA402_PROFILE_TEXT
#define CIA402_PROFILE_TEXT 1
#endif

namespace cia402 {

/// A fact is something true in this step: a decoded command, an input, a guard condition.
/// A row fires when at least one of its `any` facts holds, all of its `all` facts hold and
/// none of its `none` facts hold.
enum class fact : std::uint32_t {
  disable_voltage = 1u << 0,   ///< command decoded from the control word (words.hpp `command`)
  quick_stop = 1u << 1,
  shutdown = 1u << 2,
  switch_on = 1u << 3,
  enable_operation = 1u << 4,
  stop_and_inhibit = 1u << 5,
  fault_reset = 1u << 6,       ///< 0->1 edge of control-word bit 7 (S2)
  automatic = 1u << 7,         ///< always holds: the trigger of automatic transitions
  fault = 1u << 8,             ///< a fault cause calls for the fault reaction (T13)
  fault_quick_stop = 1u << 9,  ///< an error of class 1 (seed 001): quick stop, not T13
  fault_present = 1u << 10,    ///< any fault cause is present (T15 needs it absent)
  fault_immediate = 1u << 11,  ///< the fault reaction is to coast (class 3/4, STO, undervoltage)
  dc_link = 1u << 12,          ///< DC-link (main) voltage present (S13)
  sto = 1u << 13,              ///< safe torque off active (S14)
  overspeed = 1u << 14,        ///< |actual speed| above the profile's `speed_limit_rpm` (seed 001 T7)
  stop_complete = 1u << 15,    ///< the running stop has ended: standstill and brake engaged, or coast
  quick_stop_ends = 1u << 16,  ///< 0x605A is 1..4: QUICK STOP ACTIVE ends by itself (T12)
  quick_stop_stays = 1u << 17, ///< 0x605A is 5..8: QUICK STOP ACTIVE holds; T16 allowed
  entered_by_fault = 1u << 18, ///< the present state was entered through a fault fact (seed 001 T16)
  local_enable = 1u << 19,     ///< local request to enable the power stage (seed 001 T3/T4)
  local_disable = 1u << 20,    ///< local request to disable the power stage (seed 001 T9/T10/T12)
  fault_latched = 1u << 21,    ///< a class-4 error was seen: only a power cycle clears it
  undervoltage = 1u << 22,     ///< DC-link voltage absent: the trigger form of !dc_link (seed 001 T7)
  halt = 1u << 23,             ///< control-word bit 8 with 0x605D supported (S8)
  below_speed_limit = 1u << 24,  ///< |actual speed| below `speed_limit_rpm`, or no limit (seed 001 T2)
};

inline constexpr int fact_count = 25;

/// A set of facts.
class fact_set {
 public:
  constexpr fact_set() noexcept = default;
  constexpr fact_set(fact f) noexcept : bits_(static_cast<std::uint32_t>(f)) {}
  constexpr explicit fact_set(std::uint32_t bits) noexcept : bits_(bits) {}
  constexpr std::uint32_t bits() const noexcept { return bits_; }
  constexpr bool has(fact f) const noexcept { return (bits_ & static_cast<std::uint32_t>(f)) != 0; }
  constexpr bool empty() const noexcept { return bits_ == 0; }
  constexpr fact_set operator|(fact_set o) const noexcept { return fact_set(bits_ | o.bits_); }
  constexpr fact_set operator&(fact_set o) const noexcept { return fact_set(bits_ & o.bits_); }
  constexpr fact_set& operator|=(fact_set o) noexcept { return *this = *this | o; }
  constexpr bool operator==(fact_set o) const noexcept { return bits_ == o.bits_; }
  constexpr bool operator!=(fact_set o) const noexcept { return bits_ != o.bits_; }

 private:
  std::uint32_t bits_ = 0;
};

constexpr fact_set operator|(fact a, fact b) noexcept { return fact_set(a) | fact_set(b); }

/// "fault_reset", "dc_link", ... as written in profile files; never null.
const char* fact_name(fact f) noexcept;
bool parse_fact(std::string_view name, fact& out) noexcept;
/// The fact a decoded command raises.
constexpr fact command_fact(command c) noexcept {
  return static_cast<fact>(1u << static_cast<unsigned>(c));
}

namespace row_flag {
/// The row may fire while another row's stop is still running (S7: T9, T11, T13 take over).
inline constexpr std::uint8_t interrupts_stop = 1u << 0;
/// Taking the row clears all internal set-points (T4 in 002, T11 in 003/004).
inline constexpr std::uint8_t clears_setpoints = 1u << 1;
}  // namespace row_flag

/// One transition row, as a seed prints it: how rows are written (built-in tables, profile files)
/// and how tools read them (profile::row). A profile stores them as `stored_row`s.
struct transition_row {
  std::uint8_t number = 0;      ///< the seed's transition number, 0..17
  state to = state::start;
  std::uint16_t from = 0;       ///< set of source states (state_bit)
  fact_set any;                 ///< triggers: at least one must hold
  fact_set all;                 ///< guard: all must hold
  fact_set none;                ///< guard: none may hold
  row_stop stop = row_stop::immediate;
  std::uint8_t flags = 0;       ///< row_flag bits
};

/// A transition row as a profile stores it: its three fact sets are indices into the profile's pool
/// of distinct sets (`profile::fact_sets`). A profile has few distinct sets (the standard one 17 in
/// its 54 places), so a row takes 9 bytes instead of 18: rows are most of a profile's flash on a
/// microcontroller.
struct stored_row {
  std::uint8_t number = 0;
  state to = state::start;
  std::uint8_t from_low = 0;   ///< `from`, in two bytes so the row needs no alignment
  std::uint8_t from_high = 0;
  std::uint8_t any = 0;        ///< index into profile::fact_sets
  std::uint8_t all = 0;
  std::uint8_t none = 0;
  row_stop stop = row_stop::immediate;
  std::uint8_t flags = 0;
  constexpr std::uint16_t from() const noexcept {
    return static_cast<std::uint16_t>(from_low | (from_high << 8));
  }
};

namespace detail {
/// The index of `bits` in sets[0..count), appending it if absent: how rows' fact sets are pooled.
constexpr std::uint8_t pooled(std::uint32_t bits, std::uint32_t* sets, std::size_t& count) noexcept {
  for (std::size_t i = 0; i < count; ++i) {
    if (sets[i] == bits) return static_cast<std::uint8_t>(i);
  }
  sets[count] = bits;
  return static_cast<std::uint8_t>(count++);
}
/// Stores a row, pooling its fact sets; `sets` has room for three more.
constexpr stored_row store_row(const transition_row& r, std::uint32_t* sets, std::size_t& count) noexcept {
  stored_row s;
  s.number = r.number;
  s.to = r.to;
  s.from_low = static_cast<std::uint8_t>(r.from & 0xFFu);
  s.from_high = static_cast<std::uint8_t>(r.from >> 8);
  s.any = pooled(r.any.bits(), sets, count);
  s.all = pooled(r.all.bits(), sets, count);
  s.none = pooled(r.none.bits(), sets, count);
  s.stop = r.stop;
  s.flags = r.flags;
  return s;
}
}  // namespace detail

/// One rule of a control-word decoder: if (control_word & mask) == value, the command is `result`.
/// Rules are tried in order and the first match wins (S1). Masks may use bits 0..4 only.
struct decoder_rule {
  std::uint8_t mask = 0;
  std::uint8_t value = 0;
  command result = command::enable_operation;
};

/// What a state asks of the power stage and the motion side.
enum class state_activity : std::uint8_t {
  idle = 0,           ///< no torque, brake closed
  hold = 1,           ///< torque on, brake released, no motion (seed 003/004 SWITCHED ON)
  run = 2,            ///< torque on, motion enabled; halt (bit 8) ramps by 0x605D
  quick_stop = 3,     ///< stop by 0x605A
  fault_reaction = 4, ///< stop by 0x605E, then T14
};

/// What a state shows in the status word and what it does.
struct state_info {
  std::uint8_t status_pattern = 0;  ///< values of status bits 0..3, 5, 6 (mask 0x6F)
  state_activity activity = state_activity::idle;
};

/// Which names a profile's manuals give the bits of the control and status word: CiA 402's, or
/// DRIVECOM's STW / ZSW of the PROFIBUS drives (seeds 003 and 004: bit 8 is jog there, not halt).
enum class word_names : std::uint8_t { cia402 = 0, drivecom = 1 };

/// The option-code objects of the drive-side machine.
enum class option : std::uint8_t {
  quick_stop = 0,         ///< 0x605A
  shutdown = 1,           ///< 0x605B
  disable_operation = 2,  ///< 0x605C
  halt = 3,               ///< 0x605D
  fault_reaction = 4,     ///< 0x605E
  abort_connection = 5,   ///< 0x6007
};

inline constexpr int option_count = 6;

constexpr std::uint16_t option_index(option o) noexcept {
  constexpr std::uint16_t indices[option_count] = {0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007};
  return indices[static_cast<int>(o)];
}
/// The values the standard defines for an option-code object (cia402-reference.md §3): 0x605A
/// 0..8, 0x605B and 0x605C 0..1, 0x605D 1..4, 0x605E 0..4, 0x6007 0..3. A profile may support
/// fewer, never others.
struct option_range {
  std::int8_t lo;
  std::int8_t hi;
};
constexpr option_range standard_option_range(option o) noexcept {
  constexpr option_range ranges[option_count] = {{0, 8}, {0, 1}, {0, 1}, {1, 4}, {0, 4}, {0, 3}};
  return ranges[static_cast<int>(o)];
}

/// Maps 0x605A..0x605E and 0x6007 to their option; false for any other index.
bool option_of_index(std::uint16_t index, option& out) noexcept;

/// Which values of one option-code object a profile supports. Bit v of `supported` stands for value
/// v (0..15). An object whose `supported` is 0 does not exist in the profile (reads and writes are
/// refused), and the drive behaves as if it held `default_value`.
struct option_spec {
  std::uint16_t supported = 0;
  std::int8_t default_value = 0;
  constexpr bool exists() const noexcept { return supported != 0; }
  constexpr bool allows(std::int32_t v) const noexcept {
    return v >= 0 && v < 16 && ((supported >> v) & 1u) != 0;
  }
};

inline constexpr std::size_t max_rows = 32;

/// Bits of `axis::flags`: what the drive remembers from the previous cycle. The two that every
/// cycle reads are bits 3 and 4, so that with the state in the next byte they are a multiple of 8:
/// the compiled step (compiled.hpp) indexes its table of 8-byte entries with the axis word and one
/// mask, and no scaling.
namespace axis_flag {
inline constexpr std::uint8_t entered_by_fault = 1u << 0;  ///< the state came from a fault fact
inline constexpr std::uint8_t coast_reaction = 1u << 1;    ///< the running fault reaction coasts
inline constexpr std::uint8_t fault_latched = 1u << 2;     ///< class-4 error: only power-off clears
inline constexpr std::uint8_t fault_reset_bit = 1u << 3;   ///< bit 7 of the previous control word (S2)
inline constexpr std::uint8_t torque_on = 1u << 4;         ///< torque was on in the previous cycle
}  // namespace axis_flag

/// What profile::ordinary_entry() says of a state under a command: bits 0..5 the row that fires
/// plus 1 (0: none, quiet).
namespace ordinary {
inline constexpr std::uint8_t quiet = 0;
inline constexpr std::uint8_t row = 0x3F;
/// A row up to the match reads fact::fault_reset: a cycle with a fault-reset edge takes the full step.
inline constexpr std::uint8_t reset_reads = 1u << 6;
/// The row runs a stop first where torque is on (S7): such a cycle takes the full step.
inline constexpr std::uint8_t stops = 1u << 7;
/// Every cycle of this state and command takes the full step (no row index is 63).
inline constexpr std::uint8_t full = 0xFF;
}  // namespace ordinary
inline constexpr std::size_t max_decoder_rules = 8;

/// Rows as a profile stores them, built at compile time from rows as written:
///   constexpr cia402::transition_row my_rows[] = {...};
///   profile.use_rows(cia402::stored_rows<my_rows>);  // my_rows needs static storage
template <std::size_t NRows, std::size_t NSets>
struct stored_table {
  static_assert(NRows <= max_rows, "too many rows");
  std::array<stored_row, NRows> rows{};
  std::array<std::uint32_t, NSets> sets{};
};

namespace detail {
template <std::size_t NRows>
constexpr std::size_t distinct_fact_sets(const transition_row (&rows)[NRows]) noexcept {
  std::uint32_t sets[3 * NRows] = {};
  std::size_t count = 0;
  for (const transition_row& r : rows) store_row(r, sets, count);
  return count;
}

template <std::size_t NSets, std::size_t NRows>
constexpr stored_table<NRows, NSets> store_table(const transition_row (&rows)[NRows]) noexcept {
  std::uint32_t sets[3 * NRows] = {};
  std::size_t count = 0;
  stored_table<NRows, NSets> t;
  for (std::size_t i = 0; i < NRows; ++i) t.rows[i] = store_row(rows[i], sets, count);
  for (std::size_t i = 0; i < NSets; ++i) t.sets[i] = sets[i];
  return t;
}
}  // namespace detail

template <const auto& Rows>
inline constexpr auto stored_rows = detail::store_table<detail::distinct_fact_sets(Rows)>(Rows);

/// A profile: a view of its tables (which live in static storage, or in a `custom_profile`) plus
/// lookup tables derived from them by finalize(). Copying a profile copies the view, not the rows.
struct profile {
  const char* name = "";
  const char* seed = "";   ///< the seed file the table comes from, or "" (user profile, CIA402_PROFILE_TEXT=0)
  const char* title = "";  ///< one line for `cia402 profiles`, or "" (CIA402_PROFILE_TEXT=0)

  const decoder_rule* decoder = nullptr;
  std::uint8_t decoder_size = 0;
  const stored_row* rows = nullptr;
  std::uint8_t row_count = 0;
  /// The distinct fact sets the rows use (stored_row::any, all, none index it), as fact_set::bits().
  const std::uint32_t* fact_sets = nullptr;
  std::uint8_t fact_set_count = 0;
  std::array<state_info, state_count> states{};
  std::array<option_spec, option_count> options{};
  /// T2/T7 of seed 001 test |actual speed| against this (rpm); 0 = no such condition.
  std::int32_t speed_limit_rpm = 0;
  /// Error classes 0..4 of seed 001 are honoured; without them every fault cause calls for T13.
  bool error_classes = false;
  /// The names of the control- and status-word bits (bit_names_of()).
  word_names words = word_names::cia402;

  // Derived by finalize(): the decoder as a table over control-word bits 0..4, and per state the
  // rows that leave it (bit i = rows[i]), so a step that can fire nothing costs one AND.
  std::array<std::uint8_t, 32> command_of_bits{};
  std::array<std::uint32_t, state_count> rows_from{};
  /// The ordinary cycles compiled from the rows (ordinary_tables), or nullptr: then every cycle
  /// takes the full step. The built-in profiles point at tables compiled with them at compile time,
  /// except in a build for size (a firmware, bench/cortex_m4, whose step is the full step); a
  /// custom_profile compiles its own at finalize().
  const ordinary_tables* ordinary = nullptr;

  /// Points the profile at stored rows (stored_rows<...>) that outlive it.
  template <std::size_t NRows, std::size_t NSets>
  constexpr void use_rows(const stored_table<NRows, NSets>& t) noexcept {
    rows = t.rows.data();
    row_count = static_cast<std::uint8_t>(NRows);
    fact_sets = t.sets.data();
    fact_set_count = static_cast<std::uint8_t>(NSets);
  }

  /// Recomputes the derived tables from the data above. Call after any change to it. The ordinary
  /// cycles are compiled into `tables` where they are given (they must outlive the profile's use);
  /// without them the profile has none, and its step is the full step every cycle.
  constexpr void finalize(ordinary_tables* tables = nullptr) noexcept {
    for (unsigned bits = 0; bits < 32; ++bits) {
      std::uint8_t result = static_cast<std::uint8_t>(command::enable_operation);
      for (std::size_t r = 0; r < decoder_size; ++r) {
        if ((bits & decoder[r].mask) == decoder[r].value) {
          result = static_cast<std::uint8_t>(decoder[r].result);
          break;
        }
      }
      command_of_bits[bits] = result;
    }
    for (int s = 0; s < state_count; ++s) {
      rows_from[s] = 0;
      for (std::size_t r = 0; r < row_count && r < max_rows; ++r) {
        if ((rows[r].from() >> s) & 1u) rows_from[s] |= 1u << r;
      }
    }
    ordinary = nullptr;
    if (tables != nullptr) {
      compile_ordinary(*tables);
      ordinary = tables;
    }
  }

  /// Compiles the ordinary cycles (ordinary_tables) from ordinary_entry() of each state and command
  /// (rows_from and the decoder as finalize() leaves them).
  constexpr void compile_ordinary(ordinary_tables& t) const noexcept {
    using detail::byte_shift;
    constexpr std::uint32_t to_full_step = std::uint32_t{ordinary_action::full} << byte_shift<4>(2);
    for (unsigned key = 0; key < ordinary_tables::entry_count; ++key) {
      const std::size_t at = ordinary_tables::offset_of(key);
      t.axis_words[at / 4] = to_full_step;
      t.axis_words[at / 4 + 1] = 0;
      t.images[at / 8] = 0;
      const unsigned s = key & 0xFu, c = (key >> 4) & 7u;
      if (s >= static_cast<unsigned>(state_count) || c >= static_cast<unsigned>(command_count)) continue;
      const bool bit7 = ((key >> 7) & 1u) != 0, reset_before = ((key >> 8) & 1u) != 0,
                 torque_before = ((key >> 9) & 1u) != 0;
      const std::uint8_t code = ordinary_entry(static_cast<int>(s), c);
      // A fault-reset edge where a row reads it: the full step decides.
      if (code == ordinary::full || (bit7 && !reset_before && (code & ordinary::reset_reads) != 0)) continue;
      // Torque on where the row stops first (S7): its stop starts, unless the option code it reads
      // makes the change immediate (the full step then). A ramp 0x605D picks is read live: the full
      // step's.
      if (torque_before && (code & ordinary::stops) != 0) {
        compile_stop_start(t, at, static_cast<unsigned>(s), (code & ordinary::row) - 1u, bit7);
        continue;
      }
      // The row that fires, if any, by value: g++ with -fsanitize=undefined holds a pointer's
      // comparison with nullptr to be no constant expression, and the built-ins compile this then.
      const unsigned fired_index = code & ordinary::row;
      const bool fires = fired_index != 0;
      const stored_row r = fires ? rows[fired_index - 1] : stored_row{};
      const unsigned to = fires ? static_cast<unsigned>(r.to) : s;
      const state_activity act = states[to].activity;
      const bool torque = act != state_activity::idle;
      const unsigned actions =
          (options[static_cast<int>(option::halt)].exists() ? ordinary_action::has_halt : 0u) |
          (act == state_activity::run ? ordinary_action::runs : 0u) |
          (speed_limit_rpm > 0 ? ordinary_action::speed_limit : 0u);
      // Bit 7's flag and torque's are set anew each cycle; a row that fires clears entered_by_fault.
      const unsigned flags_kept =
          0xFFu & ~static_cast<unsigned>(axis_flag::torque_on | axis_flag::fault_reset_bit) &
          (fires ? ~static_cast<unsigned>(axis_flag::entered_by_fault) : 0xFFu);
      const unsigned flags_set = (torque ? unsigned{axis_flag::torque_on} : 0u) |
                                 (bit7 ? unsigned{axis_flag::fault_reset_bit} : 0u);
      t.axis_words[at / 4] = (flags_kept << byte_shift<4>(0)) | (actions << byte_shift<4>(2)) |
                             ((fires ? 0u : 0xFFu) << byte_shift<4>(3));
      t.axis_words[at / 4 + 1] = (flags_set << byte_shift<4>(0)) | (to << byte_shift<4>(1)) |
                                 (0xFFu << byte_shift<4>(2)) |
                                 ((fires ? unsigned{r.number} : 0u) << byte_shift<4>(3));
      const bool clear = fires && (r.flags & row_flag::clears_setpoints) != 0;
      const unsigned transition = fires ? r.number : no_transition;
      t.images[at / 8] = (std::uint64_t{to} << byte_shift<8>(0)) | (std::uint64_t{clear} << byte_shift<8>(1)) |
                         (std::uint64_t{states[to].status_pattern | 0x0210u} << detail::status_shift) |
                         (std::uint64_t{transition} << byte_shift<8>(4)) |
                         (std::uint64_t{torque} << byte_shift<8>(6)) | (std::uint64_t{torque} << byte_shift<8>(7));
    }
    for (unsigned bits = 0; bits < 256; ++bits) {
      t.row_offset[bits] = static_cast<std::uint16_t>(
          ordinary_tables::offset_of((unsigned{command_of_bits[bits & 0x1Fu]} << 4) | (bits & 0x80u)));
    }
    detail::compile_stop_entries(*this, t);
  }

  /// The entry at byte offset `at` of a key whose row (index `take`, leaving state s) starts its stop
  /// with torque on: the row becomes the pending one, the state and the last transition stay, and
  /// the outputs are the stop's (its ramp, torque on, the brake open but at standstill where the
  /// stop ends torque). The full step's way, byte for byte (the model check).
  constexpr void compile_stop_start(ordinary_tables& t, std::size_t at, unsigned s, unsigned take,
                                    bool bit7) const noexcept {
    using detail::byte_shift;
    const stored_row& r = rows[take];
    const unsigned stop = detail::stop_nibble(r.stop);
    // A ramp 0x605D picks is read as the cycle runs (S16): the image's ramp is 0, which no stop's
    // ramp is, and the step fills it in.
    const unsigned ramp = (stop & detail::stop_bits::ramp) == detail::stop_bits::halt_ramp_live
                              ? 0u
                              : stop & detail::stop_bits::ramp;
    const unsigned actions =
        ordinary_action::full | ordinary_action::stop_starts |
        ((stop & detail::stop_bits::if_code_is_1) ? ordinary_action::stop_reads_code : 0u) |
        ((stop & detail::stop_bits::code_605c) ? ordinary_action::stop_code_605c : 0u) |
        (states[static_cast<int>(r.to)].activity == state_activity::idle ? ordinary_action::stop_ends_torque : 0u) |
        (speed_limit_rpm > 0 ? ordinary_action::speed_limit : 0u);
    const unsigned flags_kept =
        0xFFu & ~static_cast<unsigned>(axis_flag::torque_on | axis_flag::fault_reset_bit);
    const unsigned flags_set = unsigned{axis_flag::torque_on} | (bit7 ? unsigned{axis_flag::fault_reset_bit} : 0u);
    t.axis_words[at / 4] = (flags_kept << byte_shift<4>(0)) | (0xFFu << byte_shift<4>(1)) |
                           (actions << byte_shift<4>(2)) | (0xFFu << byte_shift<4>(3));
    t.axis_words[at / 4 + 1] = (flags_set << byte_shift<4>(0)) | (take << byte_shift<4>(2));
    t.images[at / 8] = (std::uint64_t{s} << byte_shift<8>(0)) |
                       (std::uint64_t{states[s].status_pattern | 0x0210u} << detail::status_shift) |
                       (std::uint64_t{no_transition} << byte_shift<8>(4)) |
                       (std::uint64_t{ramp} << byte_shift<8>(5)) | (std::uint64_t{1} << byte_shift<8>(6)) |
                       (std::uint64_t{1} << byte_shift<8>(7));
  }

  /// Where the ordinary cycle of state s under command c is.
  static constexpr std::size_t ordinary_index(int s, unsigned c) noexcept {
    return static_cast<std::size_t>(s) * static_cast<std::size_t>(command_count) + c;
  }

  /// The ordinary-cycle entry of state s under command c (finalize()): the first row leaving s that
  /// fires on the facts every ordinary cycle has, unless a row before it or it reads a fact such a
  /// cycle does not fix. A fault-reset edge sets fact::fault_reset, so rows up to the match that
  /// read it mark the entry ordinary::reset_reads (the full step takes a cycle with an edge).
  constexpr std::uint8_t ordinary_entry(int s, unsigned c) const noexcept {
    const state_activity act = states[s].activity;
    if (act == state_activity::quick_stop || act == state_activity::fault_reaction) return ordinary::full;
    constexpr std::uint32_t unfixed =
        static_cast<std::uint32_t>(fact::halt) | static_cast<std::uint32_t>(fact::stop_complete) |
        static_cast<std::uint32_t>(fact::quick_stop_ends) |
        static_cast<std::uint32_t>(fact::quick_stop_stays) |
        static_cast<std::uint32_t>(fact::entered_by_fault) |
        static_cast<std::uint32_t>(fact::fault_latched);
    const std::uint32_t f = static_cast<std::uint32_t>(fact::automatic) |
                            static_cast<std::uint32_t>(fact::dc_link) |
                            static_cast<std::uint32_t>(fact::below_speed_limit) |
                            static_cast<std::uint32_t>(command_fact(static_cast<command>(c)));
    std::uint8_t reset = 0;
    for (std::size_t r = 0; r < row_count && r < max_rows; ++r) {
      if (((rows[r].from() >> s) & 1u) == 0) continue;
      const std::uint32_t any = fact_sets[rows[r].any], all = fact_sets[rows[r].all],
                          none = fact_sets[rows[r].none];
      if ((any | all | none) & unfixed) return ordinary::full;
      if ((any | all | none) & static_cast<std::uint32_t>(fact::fault_reset)) reset = ordinary::reset_reads;
      if ((any & f) && (all & f) == all && !(none & f)) {
        if (static_cast<unsigned>(rows[r].to) >= static_cast<unsigned>(state_count)) return ordinary::full;
        const state_activity to = states[static_cast<int>(rows[r].to)].activity;
        if (to == state_activity::quick_stop || to == state_activity::fault_reaction) return ordinary::full;
        return static_cast<std::uint8_t>((r + 1) | reset |
                                         (rows[r].stop != row_stop::immediate ? ordinary::stops : 0u));
      }
    }
    return reset;  // ordinary::quiet, or quiet but for an edge
  }

  /// Row i as written (i < row_count).
  constexpr transition_row row(std::size_t i) const noexcept {
    const stored_row& s = rows[i];
    transition_row r;
    r.number = s.number;
    r.to = s.to;
    r.from = s.from();
    r.any = fact_set(fact_sets[s.any]);
    r.all = fact_set(fact_sets[s.all]);
    r.none = fact_set(fact_sets[s.none]);
    r.stop = s.stop;
    r.flags = s.flags;
    return r;
  }

  /// The command that bits 0..4 of a control word decode to.
  constexpr command decode(std::uint16_t control_word) const noexcept {
    return static_cast<command>(command_of_bits[control_word & 0x1Fu]);
  }
  constexpr const state_info& info(state s) const noexcept {
    return states[static_cast<int>(s)];
  }
  constexpr const option_spec& spec(option o) const noexcept {
    return options[static_cast<int>(o)];
  }
  /// True if torque may be on in state s (its activity is not idle): the safety invariant.
  constexpr bool torque_allowed(state s) const noexcept {
    return info(s).activity != state_activity::idle;
  }
  /// The status-word bits showing state s (bits 0..3, 5, 6).
  constexpr std::uint16_t status_pattern(state s) const noexcept { return info(s).status_pattern; }
};

/// A profile that owns its tables: what a profile file loads into. No heap; copies re-point.
class custom_profile {
 public:
  custom_profile() noexcept { repoint(); }
  custom_profile(const custom_profile& o) noexcept { *this = o; }
  custom_profile& operator=(const custom_profile& o) noexcept {
    name_ = o.name_; seed_ = o.seed_; title_ = o.title_;
    decoder_ = o.decoder_; rows_ = o.rows_; fact_sets_ = o.fact_sets_; view_ = o.view_;
    ordinary_ = o.ordinary_;
    repoint();
    return *this;
  }
  /// Starts from a copy of another profile (built-in or not), tables included.
  explicit custom_profile(const profile& base) noexcept;

  const profile& get() const noexcept { return view_; }
  operator const profile&() const noexcept { return view_; }  // NOLINT: a custom profile is a profile

  bool set_name(std::string_view s) noexcept { return assign(name_, s); }
  bool set_seed(std::string_view s) noexcept { return assign(seed_, s); }
  bool set_title(std::string_view s) noexcept { return assign(title_, s); }
  /// Replace the tables; false (and no change) if they exceed the capacities. set_rows stores the
  /// rows with their fact sets pooled.
  bool set_decoder(const decoder_rule* rules, std::size_t n) noexcept;
  bool set_rows(const transition_row* rows, std::size_t n) noexcept;
  /// The rest of the profile (states, options, flags); tables and names are kept.
  profile& settings() noexcept { return view_; }
  /// Recompute the derived tables; call after any change.
  void finalize() noexcept { repoint(); view_.finalize(&ordinary_); }

 private:
  template <std::size_t N>
  static bool assign(std::array<char, N>& to, std::string_view s) noexcept {
    if (s.size() >= N) return false;
    for (std::size_t i = 0; i < N; ++i) to[i] = i < s.size() ? s[i] : '\0';
    return true;
  }
  void repoint() noexcept {
    view_.name = name_.data(); view_.seed = seed_.data(); view_.title = title_.data();
    view_.decoder = decoder_.data(); view_.rows = rows_.data(); view_.fact_sets = fact_sets_.data();
    // Its own compiled cycles where it has them: a copy must not point at the other's.
    if (view_.ordinary != nullptr) view_.ordinary = &ordinary_;
  }
  std::array<char, 40> name_{};
  std::array<char, 64> seed_{};
  std::array<char, 128> title_{};
  std::array<decoder_rule, max_decoder_rules> decoder_{};
  std::array<stored_row, max_rows> rows_{};
  std::array<std::uint32_t, 3 * max_rows> fact_sets_{};
  ordinary_tables ordinary_{};
  profile view_{};
};

/// The 16 bits of the control and status word by name, as the profile's manuals call them, and the
/// words' own names ("controlword 0x6040", "control word STW (0x6040)").
struct word_bit_names {
  const char* control_word;
  const char* status_word;
  const char* control[16];
  const char* status[16];
};
const word_bit_names& bit_names_of(const profile& p) noexcept;
/// "cia402" / "drivecom", as profile files spell them; parse_word_names refuses anything else.
const char* word_names_name(word_names w) noexcept;
bool parse_word_names(std::string_view name, word_names& out) noexcept;

/// The built-in profiles: cia402, no-quick-stop, lexium32, s300-profibus, ax2000-profibus.
std::size_t builtin_profile_count() noexcept;
const profile& builtin_profile(std::size_t i) noexcept;
/// The built-in profile of that name, or nullptr.
const profile* find_builtin_profile(std::string_view name) noexcept;
/// The standard profile, `cia402` (seed 002 and semantics.md).
const profile& standard_profile() noexcept;

/// Checks a profile for mistakes a table can hold: rows from no state, a destination out of range,
/// decoder masks outside bits 0..4, a row or option default the profile cannot honour.
/// Returns nullptr when the profile is sound, else a reason; `row` gets the offending row index or -1.
const char* check_profile(const profile& p, int& row) noexcept;

}  // namespace cia402

#include "cia402/detail/stop_entries.hpp"
