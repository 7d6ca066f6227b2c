// Profile files: TOML in, cia402::custom_profile out, and back. The loader builds the whole profile
// aside and hands it over only once every key, name and range and then check_profile() have passed,
// so a caller sees a complete profile or an error, never a half-loaded one.
#include "cia402/profile_file.hpp"

#include "cia402/support/text.hpp"
#include "cia402/support/toml_reading.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

static_assert(TOML_EXCEPTIONS, "the loader relies on toml::parse throwing toml::parse_error");

namespace cia402 {
namespace {

// ---------------------------------------------------------------------------------------------
// Names that only profile files spell; the core names states and facts itself.

constexpr const char* row_stop_names[] = {
    "immediate",       "shutdown_option", "disable_operation_option", "slow_down_ramp",
    "quick_stop_ramp", "halt_ramp",       "shutdown_option_halt",
};
static_assert(sizeof(row_stop_names) / sizeof(row_stop_names[0]) == row_stop_count);

constexpr const char* activity_names[] = {"idle", "hold", "run", "quick_stop", "fault_reaction"};
constexpr int activity_count = 5;

// Case-insensitive, '-' and '_' alike, as the core's own name parsers.
bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto fold = [](char c) {
      if (c == '-') return '_';
      return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    };
    if (fold(a[i]) != fold(b[i])) return false;
  }
  return true;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool parse_command(std::string_view name, command& out) {
  for (int i = 0; i < command_count; ++i) {
    if (same_name(name, command_name(static_cast<command>(i)))) {
      out = static_cast<command>(i);
      return true;
    }
  }
  return false;
}

template <typename Enum, std::size_t N>
bool parse_listed(std::string_view name, const char* const (&names)[N], Enum& out) {
  for (std::size_t i = 0; i < N; ++i) {
    if (same_name(name, names[i])) {
      out = static_cast<Enum>(i);
      return true;
    }
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Refusals travel as an exception inside this file only (toml_reading.hpp); the public API returns
// them as values.

using support::hex;
using toml_reading::check_keys;
using toml_reading::get_array;
using toml_reading::get_bool;
using toml_reading::get_int;
using toml_reading::get_string;
using toml_reading::get_table;
using toml_reading::quoted;
using toml_reading::refusal;
using toml_reading::refuse;
using toml_reading::refuse_type;
using toml_reading::require;

const toml::node* find(const toml::table& t, std::string_view key) { return t.get(key); }

state get_state(const toml::node& n, std::string_view what) {
  const std::string_view name = get_string(n, what);
  state s;
  if (!parse_state(name, s))
    refuse(n, "unknown state " + quoted(name) + " in " + std::string(what));
  return s;
}

fact_set get_facts(const toml::node& n, std::string_view what) {
  fact_set set;
  for (const toml::node& item : get_array(n, what)) {
    const std::string_view name = get_string(item, std::string(what) + " entry");
    fact f;
    if (!parse_fact(name, f))
      refuse(item, "unknown fact " + quoted(name) + " in " + std::string(what));
    if (set.has(f))
      refuse(item, "fact " + quoted(name) + " is listed twice in " + std::string(what));
    set |= fact_set(f);
  }
  return set;
}

// The option objects are keyed by their index, e.g. [options.0x605A].
bool parse_option_key(std::string_view key, option& out) {
  if (key.size() != 6 || key[0] != '0' || (key[1] != 'x' && key[1] != 'X')) return false;
  unsigned v = 0;
  for (std::size_t i = 2; i < key.size(); ++i) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(key[i])));
    if (c >= '0' && c <= '9')
      v = v * 16 + static_cast<unsigned>(c - '0');
    else if (c >= 'a' && c <= 'f')
      v = v * 16 + static_cast<unsigned>(c - 'a' + 10);
    else
      return false;
  }
  return option_of_index(static_cast<std::uint16_t>(v), out);
}

// ---------------------------------------------------------------------------------------------
// The loader proper.

constexpr std::size_t name_capacity = 39;  // custom_profile stores 40 chars with the terminator
constexpr std::size_t seed_capacity = 63;
constexpr std::size_t title_capacity = 127;

std::string_view get_text(const toml::node& n, std::string_view what, std::size_t capacity,
                          bool allow_empty) {
  const std::string_view s = get_string(n, what);
  if (s.size() > capacity) {
    refuse(n, std::string(what) + " is longer than " + std::to_string(capacity) + " characters");
  }
  if (!allow_empty && s.empty()) refuse(n, std::string(what) + " must not be empty");
  if (s.find('\0') != std::string_view::npos) refuse(n, std::string(what) + " contains a NUL");
  return s;
}

void load_decoder(const toml::node& node, custom_profile& out) {
  const toml::array& rules = get_array(node, "decoder");
  if (rules.empty())
    refuse(node, "decoder has no rules: every control word would be enable_operation");
  decoder_rule table[max_decoder_rules];
  std::size_t n = 0;
  for (const toml::node& item : rules) {
    if (n == max_decoder_rules) {
      refuse(item, "more than " + std::to_string(max_decoder_rules) + " decoder rules");
    }
    const toml::table& t = get_table(item, "a decoder rule");
    check_keys(t, {"mask", "value", "command"}, "a decoder rule");
    const toml::node& mask_node = require(t, "mask", "a decoder rule");
    const std::int64_t mask = get_int(mask_node, "mask", 0, 0xFFFF);
    if ((mask & ~std::int64_t{0x1F}) != 0) {
      refuse(mask_node, "mask " + hex(static_cast<unsigned>(mask), 2) +
                            " uses control-word bits outside 0..4");
    }
    const toml::node& value_node = require(t, "value", "a decoder rule");
    const std::int64_t value = get_int(value_node, "value", 0, 0xFFFF);
    if ((value & ~mask) != 0) {
      refuse(value_node, "value " + hex(static_cast<unsigned>(value), 2) +
                             " has bits outside its mask " + hex(static_cast<unsigned>(mask), 2));
    }
    const toml::node& command_node = require(t, "command", "a decoder rule");
    const std::string_view command_text = get_string(command_node, "command");
    command c;
    if (!parse_command(command_text, c)) {
      refuse(command_node, "unknown command " + quoted(command_text));
    }
    table[n++] = decoder_rule{static_cast<std::uint8_t>(mask), static_cast<std::uint8_t>(value), c};
  }
  out.set_decoder(table, n);
}

// Returns the source region of each row, for check_profile's row index.
std::vector<toml::source_region> load_rows(const toml::node& node, custom_profile& out) {
  const toml::array& rows = get_array(node, "rows");
  if (rows.empty()) refuse(node, "rows is empty: the drive could never leave START");
  transition_row table[max_rows];
  std::vector<toml::source_region> where;
  std::size_t n = 0;
  bool leaves_start = false;
  for (const toml::node& item : rows) {
    if (n == max_rows) {
      refuse(item, "more than " + std::to_string(max_rows) + " transition rows");
    }
    const toml::table& t = get_table(item, "a row");
    check_keys(t,
               {"number", "from", "to", "any", "all", "none", "stop", "interrupts_stop",
                "clears_setpoints"},
               "a row");
    transition_row r;
    r.number = static_cast<std::uint8_t>(get_int(require(t, "number", "a row"), "number", 0, 17));

    const toml::node& from_node = require(t, "from", "a row");
    const toml::array& from = get_array(from_node, "from");
    if (from.empty()) refuse(from_node, "row T" + std::to_string(r.number) + " leaves no state");
    for (const toml::node& s : from) {
      const state st = get_state(s, "from");
      if (r.from & state_bit(st)) {
        refuse(s, "state " + quoted(get_string(s, "from")) + " is listed twice in from");
      }
      r.from = static_cast<std::uint16_t>(r.from | state_bit(st));
    }
    if (r.from & state_bit(state::start)) leaves_start = true;

    const toml::node& to_node = require(t, "to", "a row");
    r.to = get_state(to_node, "to");
    if (r.to == state::start) refuse(to_node, "a row cannot go to START");

    const toml::node& any_node = require(t, "any", "a row");
    r.any = get_facts(any_node, "any");
    if (r.any.empty())
      refuse(any_node, "row T" + std::to_string(r.number) + " has no trigger in any");
    if (const toml::node* all = find(t, "all")) r.all = get_facts(*all, "all");
    if (const toml::node* none = find(t, "none")) {
      r.none = get_facts(*none, "none");
      if ((r.all & r.none) != fact_set()) {
        refuse(*none, "row T" + std::to_string(r.number) + " requires and forbids the same fact");
      }
    }
    if (const toml::node* stop = find(t, "stop")) {
      const std::string_view name = get_string(*stop, "stop");
      if (!parse_listed(name, row_stop_names, r.stop)) {
        refuse(*stop, "unknown stop " + quoted(name) +
                          " (immediate, shutdown_option, disable_operation_option, slow_down_ramp, "
                          "quick_stop_ramp, halt_ramp, shutdown_option_halt)");
      }
    }
    if (const toml::node* f = find(t, "interrupts_stop"); f && get_bool(*f, "interrupts_stop")) {
      r.flags = static_cast<std::uint8_t>(r.flags | row_flag::interrupts_stop);
    }
    if (const toml::node* f = find(t, "clears_setpoints"); f && get_bool(*f, "clears_setpoints")) {
      r.flags = static_cast<std::uint8_t>(r.flags | row_flag::clears_setpoints);
    }
    table[n++] = r;
    where.push_back(t.source());
  }
  if (!leaves_start) refuse(node, "no row leaves START (T0): the drive would never power up");
  out.set_rows(table, n);
  return where;
}

void load_states(const toml::node& node, profile& p, bool complete) {
  const toml::table& states = get_table(node, "states");
  bool given[state_count] = {};
  for (auto&& [key, value] : states) {
    state s;
    if (!parse_state(key.str(), s))
      refuse(key, "unknown state " + quoted(key.str()) + " in states");
    if (given[static_cast<int>(s)]) {
      refuse(key, "state " + quoted(key.str()) + " is given twice in states");
    }
    given[static_cast<int>(s)] = true;
    const std::string where = "states." + std::string(key.str());
    const toml::table& t = get_table(value, where);
    check_keys(t, {"status", "activity"}, where);
    state_info& info = p.states[static_cast<int>(s)];
    if (const toml::node* status = find(t, "status")) {
      const std::int64_t v = get_int(*status, "status", 0, 0xFFFF);
      if ((v & ~std::int64_t{status_bit::state_bits}) != 0) {
        refuse(*status, "status pattern " + hex(static_cast<unsigned>(v), 4) +
                            " uses bits other than 0..3, 5, 6");
      }
      info.status_pattern = static_cast<std::uint8_t>(v);
    } else if (complete) {
      refuse(t, where + " lacks the key 'status'");
    }
    if (const toml::node* activity = find(t, "activity")) {
      const std::string_view name = get_string(*activity, "activity");
      if (!parse_listed(name, activity_names, info.activity)) {
        refuse(*activity, "unknown activity " + quoted(name) +
                              " (idle, hold, run, quick_stop, fault_reaction)");
      }
    } else if (complete) {
      refuse(t, where + " lacks the key 'activity'");
    }
  }
  if (complete) {
    // START is never shown by a status word of its own, so a file may leave it out.
    for (int s = 1; s < state_count; ++s) {
      if (!given[s]) {
        refuse(node, "states lacks " + lower(state_name(static_cast<state>(s))) +
                         " (every state must be given when there is no base)");
      }
    }
  }
}

void load_options(const toml::node& node, profile& p, bool complete) {
  const toml::table& options = get_table(node, "options");
  bool given[option_count] = {};
  for (auto&& [key, value] : options) {
    option o;
    if (!parse_option_key(key.str(), o)) {
      refuse(key, "unknown option object " + quoted(key.str()) +
                      " (0x605A, 0x605B, 0x605C, 0x605D, 0x605E, 0x6007)");
    }
    const int oi = static_cast<int>(o);
    if (given[oi]) refuse(key, "option " + quoted(key.str()) + " is given twice");
    given[oi] = true;
    const std::string where = "options." + std::string(key.str());
    const toml::table& t = get_table(value, where);
    check_keys(t, {"supported", "default"}, where);
    option_spec spec = p.options[oi];
    const option_range range = standard_option_range(o);
    const toml::node* supported = find(t, "supported");
    if (supported != nullptr) {
      spec.supported = 0;
      for (const toml::node& item : get_array(*supported, "supported")) {
        const std::int64_t v = get_int(item, "supported value of " + where, range.lo, range.hi);
        if (spec.supported & (1u << v)) {
          refuse(item, "value " + std::to_string(v) + " is listed twice in supported");
        }
        spec.supported = static_cast<std::uint16_t>(spec.supported | (1u << v));
      }
    } else if (complete) {
      refuse(t, where + " lacks the key 'supported'");
    }
    const toml::node* def = find(t, "default");
    if (def != nullptr) {
      spec.default_value =
          static_cast<std::int8_t>(get_int(*def, "default of " + where, range.lo, range.hi));
      if (spec.exists() && !spec.allows(spec.default_value)) {
        refuse(*def, "default " + std::to_string(spec.default_value) +
                         " is not a supported value of " + where);
      }
    } else if (complete) {
      refuse(t, where + " lacks the key 'default'");
    } else if (spec.exists() && !spec.allows(spec.default_value)) {
      refuse(*supported, "the inherited default " + std::to_string(spec.default_value) +
                             " is not among the supported values of " + where);
    }
    p.options[oi] = spec;
  }
  if (complete) {
    for (int o = 0; o < option_count; ++o) {
      if (!given[o]) {
        refuse(node, "options lacks " + hex(option_index(static_cast<option>(o)), 4) +
                         " (every option object must be given when there is no base)");
      }
    }
  }
}

custom_profile load(const toml::table& root) {
  check_keys(root,
             {"base", "name", "seed", "title", "speed_limit_rpm", "error_classes", "word_names",
              "decoder", "rows", "states", "options"},
             "the profile");

  custom_profile out;
  const toml::node* base = find(root, "base");
  if (base != nullptr) {
    const std::string_view name = get_string(*base, "base");
    const profile* b = find_builtin_profile(name);
    if (b == nullptr) {
      std::string list;
      for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
        list += (i ? ", " : "") + std::string(builtin_profile(i).name);
      }
      refuse(*base, "unknown base profile " + quoted(name) + " (built-in: " + list + ")");
    }
    out = custom_profile(*b);
  }
  // Without a base nothing is inherited, so every table must be given in full.
  const bool complete = base == nullptr;

  if (const toml::node* n = find(root, "name")) {
    out.set_name(get_text(*n, "name", name_capacity, false));
  } else if (complete) {
    refuse(root, "the profile lacks the key 'name'");
  }
  if (const toml::node* n = find(root, "seed"))
    out.set_seed(get_text(*n, "seed", seed_capacity, true));
  if (const toml::node* n = find(root, "title")) {
    out.set_title(get_text(*n, "title", title_capacity, true));
  }

  profile& p = out.settings();
  if (const toml::node* n = find(root, "speed_limit_rpm")) {
    p.speed_limit_rpm = static_cast<std::int32_t>(
        get_int(*n, "speed_limit_rpm", 0, std::numeric_limits<std::int32_t>::max()));
  }
  if (const toml::node* n = find(root, "error_classes")) {
    p.error_classes = get_bool(*n, "error_classes");
  }
  if (const toml::node* n = find(root, "word_names")) {
    const std::string_view name = get_string(*n, "word_names");
    if (!parse_word_names(name, p.words)) {
      refuse(*n, "unknown word_names " + quoted(name) + " (cia402, drivecom)");
    }
  }

  if (const toml::node* n = find(root, "decoder")) {
    load_decoder(*n, out);
  } else if (complete) {
    refuse(root, "the profile lacks the key 'decoder'");
  }
  std::vector<toml::source_region> row_sources;
  if (const toml::node* n = find(root, "rows")) {
    row_sources = load_rows(*n, out);
  } else if (complete) {
    refuse(root, "the profile lacks the key 'rows'");
  }
  if (const toml::node* n = find(root, "states")) {
    load_states(*n, out.settings(), complete);
  } else if (complete) {
    refuse(root, "the profile lacks the key 'states'");
  }
  if (const toml::node* n = find(root, "options")) {
    load_options(*n, out.settings(), complete);
  } else if (complete) {
    refuse(root, "the profile lacks the key 'options'");
  }

  out.finalize();
  int bad_row = -1;
  if (const char* reason = check_profile(out.get(), bad_row)) {
    if (bad_row >= 0 && static_cast<std::size_t>(bad_row) < row_sources.size()) {
      refuse(row_sources[static_cast<std::size_t>(bad_row)], reason);
    }
    throw refusal{0, 0, reason};
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Writing.

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) {
          out += "\\u00" + hex(static_cast<unsigned char>(c), 2).substr(2);
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string fact_list(fact_set set) {
  std::string out = "[";
  for (int i = 0; i < fact_count; ++i) {
    const fact f = static_cast<fact>(1u << i);
    if (set.has(f)) out += (out.size() > 1 ? ", \"" : "\"") + std::string(fact_name(f)) + "\"";
  }
  return out + "]";
}

std::string state_list(std::uint16_t states) {
  std::string out = "[";
  for (int i = 0; i < state_count; ++i) {
    if ((states >> i) & 1u) {
      out += (out.size() > 1 ? ", \"" : "\"") + lower(state_name(static_cast<state>(i))) + "\"";
    }
  }
  return out + "]";
}

}  // namespace

std::string profile_file_error::message() const {
  return support::located_message(source_name, "<profile>", line, column, reason);
}

const char* row_stop_name(row_stop s) noexcept {
  const auto i = static_cast<unsigned>(s);
  return i < static_cast<unsigned>(row_stop_count) ? row_stop_names[i] : "unknown";
}

const char* state_activity_name(state_activity a) noexcept {
  const auto i = static_cast<unsigned>(a);
  return i < static_cast<unsigned>(activity_count) ? activity_names[i] : "unknown";
}

profile_load_result load_profile_toml(std::string_view text, std::string_view source_name) {
  const std::string name(source_name);
  std::optional<custom_profile> loaded;
  if (const auto bad = toml_reading::parse_and_load(text, name, [&loaded](const toml::table& root) { loaded = load(root); })) {
    return profile_file_error{bad->line, bad->column, bad->reason, name};
  }
  return std::move(*loaded);
}

profile_load_result load_profile_toml_file(const std::string& path) {
  std::string why;
  const std::optional<std::string> text = toml_reading::read_small_file(path, why);
  if (!text) return profile_file_error{0, 0, why, path};
  return load_profile_toml(*text, path);
}

std::string dump_profile_toml(const profile& p) {
  std::ostringstream o;
  o << "# cia402 profile file (see examples/profiles/custom-drive.toml for the format).\n"
    << "# Written from the profile " << toml_string(p.name)
    << "; self-contained: it names no base.\n\n";
  o << "name = " << toml_string(p.name) << "\n";
  o << "seed = " << toml_string(p.seed) << "\n";
  o << "title = " << toml_string(p.title) << "\n";
  o << "speed_limit_rpm = " << p.speed_limit_rpm << "\n";
  o << "error_classes = " << (p.error_classes ? "true" : "false") << "\n";
  o << "# The names of the control- and status-word bits: cia402, or drivecom (PROFIBUS STW/ZSW).\n"
    << "word_names = \"" << word_names_name(p.words) << "\"\n";

  o << "\n# Control-word decoder over bits 0..4: the first rule whose (word & mask) == value\n"
    << "# wins; a word no rule matches is enable_operation.\n";
  for (std::size_t i = 0; i < p.decoder_size; ++i) {
    const decoder_rule& d = p.decoder[i];
    o << "[[decoder]]\nmask = " << hex(d.mask, 2) << "\nvalue = " << hex(d.value, 2)
      << "\ncommand = \"" << lower(command_name(d.result)) << "\"\n";
  }

  o << "\n# Transition rows, tried in this order; the first whose facts hold fires.\n";
  for (std::size_t i = 0; i < p.row_count; ++i) {
    const transition_row r = p.row(i);
    o << "\n[[rows]]\nnumber = " << static_cast<int>(r.number) << "\n";
    o << "from = " << state_list(r.from) << "\n";
    o << "to = \"" << lower(state_name(r.to)) << "\"\n";
    o << "any = " << fact_list(r.any) << "\n";
    if (!r.all.empty()) o << "all = " << fact_list(r.all) << "\n";
    if (!r.none.empty()) o << "none = " << fact_list(r.none) << "\n";
    if (r.stop != row_stop::immediate) o << "stop = \"" << row_stop_name(r.stop) << "\"\n";
    if (r.flags & row_flag::interrupts_stop) o << "interrupts_stop = true\n";
    if (r.flags & row_flag::clears_setpoints) o << "clears_setpoints = true\n";
  }

  o << "\n# Status bits 0..3, 5, 6 each state shows, and what it asks of the power stage.\n";
  for (int s = 0; s < state_count; ++s) {
    const state_info& info = p.states[static_cast<std::size_t>(s)];
    o << "[states." << lower(state_name(static_cast<state>(s)))
      << "]\nstatus = " << hex(info.status_pattern, 2) << "\nactivity = \""
      << state_activity_name(info.activity) << "\"\n";
  }

  o << "\n# Option-code objects: the values a write may set (empty: the object does not exist)\n"
    << "# and the value the drive starts with (or always uses, when the object does not exist).\n";
  for (int i = 0; i < option_count; ++i) {
    const option_spec& spec = p.options[static_cast<std::size_t>(i)];
    o << "[options." << hex(option_index(static_cast<option>(i)), 4) << "]\nsupported = [";
    bool first = true;
    for (int v = 0; v < 16; ++v) {
      if ((spec.supported >> v) & 1u) {
        o << (first ? "" : ", ") << v;
        first = false;
      }
    }
    o << "]\ndefault = " << static_cast<int>(spec.default_value) << "\n";
  }
  return o.str();
}

}  // namespace cia402
