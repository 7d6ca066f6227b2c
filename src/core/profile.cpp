#include "cia402/profile.hpp"

#include "profiles/builtin.hpp"

namespace cia402 {
namespace {

const profile* const builtins[] = {
    &detail::cia402_profile,         &detail::no_quick_stop_profile,
    &detail::lexium32_profile,       &detail::s300_profibus_profile,
    &detail::ax2000_profibus_profile,
};
constexpr std::size_t builtin_count = sizeof(builtins) / sizeof(builtins[0]);

bool same(std::string_view a, const char* b) noexcept { return a == std::string_view(b); }

}  // namespace

std::size_t builtin_profile_count() noexcept { return builtin_count; }

const profile& builtin_profile(std::size_t i) noexcept {
  return *builtins[i < builtin_count ? i : 0];
}

const profile* find_builtin_profile(std::string_view name) noexcept {
  for (const profile* p : builtins) {
    if (same(name, p->name)) return p;
  }
  return nullptr;
}

const profile& standard_profile() noexcept { return detail::cia402_profile; }

bool option_of_index(std::uint16_t index, option& out) noexcept {
  // Most indices asked about are not option codes (every set-point write asks): one range test.
  if (index != 0x6007 && (index < 0x605A || index > 0x605E)) return false;
  for (int i = 0; i < option_count; ++i) {
    if (option_index(static_cast<option>(i)) == index) {
      out = static_cast<option>(i);
      return true;
    }
  }
  return false;
}

const char* check_profile(const profile& p, int& row) noexcept {
  row = -1;
  if (p.row_count > max_rows) return "more than 32 transition rows";
  if (p.decoder_size > max_decoder_rules) return "more than 8 decoder rules";
  if (p.row_count > 0 && (p.rows == nullptr || p.fact_sets == nullptr)) return "rows missing";
  if (p.decoder_size > 0 && p.decoder == nullptr) return "decoder missing";
  for (std::size_t i = 0; i < p.decoder_size; ++i) {
    const decoder_rule& d = p.decoder[i];
    if ((d.mask & ~0x1Fu) != 0) return "a decoder rule masks bits other than 0..4";
    if ((d.value & ~d.mask) != 0) return "a decoder rule's value has bits outside its mask";
    if (static_cast<unsigned>(d.result) >= static_cast<unsigned>(command_count)) {
      return "a decoder rule yields an unknown command";
    }
  }
  constexpr std::uint32_t all_facts = (1u << fact_count) - 1;
  for (std::size_t i = 0; i < p.row_count; ++i) {
    row = static_cast<int>(i);
    const stored_row& s = p.rows[i];
    if (s.any >= p.fact_set_count || s.all >= p.fact_set_count || s.none >= p.fact_set_count) {
      return "row names a fact set the profile does not have";
    }
    const transition_row r = p.row(i);
    if (r.number > 17) return "transition number outside 0..17";
    if (r.from == 0) return "row leaves no state";
    if ((r.from >> state_count) != 0) return "row leaves an unknown state";
    if (static_cast<unsigned>(r.to) >= static_cast<unsigned>(state_count) || r.to == state::start) {
      return "row goes to an unknown state";
    }
    if (r.any.empty()) return "row has no trigger";
    if (((r.any | r.all | r.none).bits() & ~all_facts) != 0) return "row uses an unknown fact";
    if ((r.all & r.none) != fact_set()) return "row requires and forbids the same fact";
    if (static_cast<unsigned>(r.stop) >= static_cast<unsigned>(row_stop_count)) {
      return "row has an unknown stop";
    }
    if ((r.flags & ~(row_flag::interrupts_stop | row_flag::clears_setpoints)) != 0) {
      return "row has unknown flags";
    }
  }
  row = -1;
  // The drive has no meaning for a value the standard does not define.
  for (int o = 0; o < option_count; ++o) {
    const option_spec& s = p.options[o];
    const option_range range = standard_option_range(static_cast<option>(o));
    const auto standard_values = static_cast<std::uint16_t>(((1u << (range.hi + 1)) - 1u) &
                                                            ~((1u << range.lo) - 1u));
    if (s.exists() && !s.allows(s.default_value)) return "an option code's default is not supported";
    if ((s.supported & ~standard_values) != 0) {
      return "an option code supports a value the standard does not define";
    }
    if (!s.exists() && (s.default_value < range.lo || s.default_value > range.hi)) {
      return "an option code's fixed value is out of range";
    }
  }
  if (p.words != word_names::cia402 && p.words != word_names::drivecom) return "unknown word names";
  for (int s = 0; s < state_count; ++s) {
    if ((p.states[s].status_pattern & ~0x6Fu) != 0) return "a status pattern uses bits other than 0..3, 5, 6";
    if (static_cast<unsigned>(p.states[s].activity) > static_cast<unsigned>(state_activity::fault_reaction)) {
      return "a state has an unknown activity";
    }
  }
  return nullptr;
}

custom_profile::custom_profile(const profile& base) noexcept {
  view_ = base;
  set_name(base.name);
  set_seed(base.seed);
  set_title(base.title);
  set_decoder(base.decoder, base.decoder_size);
  std::array<transition_row, max_rows> rows{};
  const std::size_t n = base.row_count < max_rows ? base.row_count : max_rows;
  for (std::size_t i = 0; i < n; ++i) rows[i] = base.row(i);
  set_rows(rows.data(), n);
  finalize();
}

bool custom_profile::set_decoder(const decoder_rule* rules, std::size_t n) noexcept {
  if (n > max_decoder_rules || (n > 0 && rules == nullptr)) return false;
  for (std::size_t i = 0; i < n; ++i) decoder_[i] = rules[i];
  view_.decoder_size = static_cast<std::uint8_t>(n);
  return true;
}

bool custom_profile::set_rows(const transition_row* rows, std::size_t n) noexcept {
  if (n > max_rows || (n > 0 && rows == nullptr)) return false;
  std::size_t sets = 0;
  for (std::size_t i = 0; i < n; ++i) rows_[i] = detail::store_row(rows[i], fact_sets_.data(), sets);
  view_.row_count = static_cast<std::uint8_t>(n);
  view_.fact_set_count = static_cast<std::uint8_t>(sets);
  return true;
}

}  // namespace cia402
