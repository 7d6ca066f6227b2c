// Reading TOML for the project's own file formats (profile files, simulator scenarios): typed
// getters that refuse with the line, the column and a reason, and a check that refuses unknown
// keys so a typo never passes as "not given". Internal to the tools layer: refusals travel as the
// exception `refusal` inside a loader, which returns them as values.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace cia402::toml_reading {

struct refusal {
  int line = 0;
  int column = 0;
  std::string reason;
};

[[noreturn]] void refuse(const toml::source_region& at, std::string reason);
[[noreturn]] void refuse(const toml::node& at, std::string reason);
[[noreturn]] void refuse(const toml::key& at, std::string reason);
[[noreturn]] void refuse_type(const toml::node& n, std::string_view what, std::string_view expected);

/// "'text'".
std::string quoted(std::string_view s);
/// "an integer", "a table", ... for messages.
const char* type_name(const toml::node& n);

/// Refuses the first key of `t` not in `allowed`; `hint`, when given, may add to the reason.
void check_keys(const toml::table& t, std::initializer_list<std::string_view> allowed,
                std::string_view where,
                const std::function<std::string(std::string_view key)>& hint = {});

const toml::node& require(const toml::table& t, std::string_view key, std::string_view where);
std::int64_t get_int(const toml::node& n, std::string_view what, std::int64_t lo, std::int64_t hi);
std::string_view get_string(const toml::node& n, std::string_view what);
bool get_bool(const toml::node& n, std::string_view what);
const toml::array& get_array(const toml::node& n, std::string_view what);
const toml::table& get_table(const toml::node& n, std::string_view what);

/// The largest profile or scenario file read (the built-in ones are a few KiB).
inline constexpr std::size_t max_file_bytes = 1 << 20;

/// Checks text before the TOML parser sees it, because toml++ 3.3.0 (Debian 12's) reaches
/// undefined behaviour on some non-ASCII input: at most max_file_bytes, no NUL, valid UTF-8, and
/// non-ASCII characters only inside strings and comments (keys and bare values are ASCII in every
/// format the project reads). The refusal names the line and column of the first offending byte.
std::optional<refusal> check_toml_text(std::string_view text);

/// Checks the text (check_toml_text), parses it and hands the root table to `load`: what is wrong
/// with the text, a TOML syntax error, or a refusal `load` throws comes back with its place;
/// nothing when `load` returned.
std::optional<refusal> parse_and_load(std::string_view text, std::string_view source_name,
                                      const std::function<void(const toml::table& root)>& load);

/// The contents of a regular file of at most max_file_bytes, or the reason it cannot be had (not
/// a regular file: a device, a FIFO, a directory; too large; unreadable). Never echoes the file.
std::optional<std::string> read_small_file(const std::string& path, std::string& why);

}  // namespace cia402::toml_reading
