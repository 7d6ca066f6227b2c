#include "cli/common.hpp"

#include <CLI/CLI.hpp>
#include <fstream>
#include <limits>
#include <ostream>
#include <variant>

#include "cia402/profile_file.hpp"

namespace cia402::cli {
namespace {

volatile std::sig_atomic_t stop_flag = 0;
extern "C" void on_stop_signal(int) { stop_flag = 1; }

}  // namespace

stop_signals::stop_signals() {
  stop_flag = 0;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &old_int_);
  sigaction(SIGTERM, &action, &old_term_);
}

stop_signals::~stop_signals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

const volatile std::sig_atomic_t& stop_signals::flag() noexcept { return stop_flag; }

std::optional<std::int64_t> parse_number(std::string_view text) {
  return support::parse_integer(text, std::numeric_limits<std::int32_t>::min(),
                                std::numeric_limits<std::uint32_t>::max());
}

bool open_output(std::ofstream& file, const std::string& path, std::string_view command, std::ostream& err,
                 std::ios::openmode mode) {
  file.open(path, mode | std::ios::out);
  if (file) return true;
  err << "cia402 " << command << ": cannot write " << path << "\n";
  return false;
}

std::string builtin_profile_names() {
  std::string list;
  for (std::size_t i = 0; i < builtin_profile_count(); ++i) {
    list += (i ? ", " : "") + std::string(builtin_profile(i).name);
  }
  return list;
}

bool profile_choice::resolve(const std::string& name, const std::string& file, std::ostream& err) {
  if (!file.empty()) {
    profile_load_result result = load_profile_toml_file(file);
    if (const auto* error = std::get_if<profile_file_error>(&result)) {
      err << "cia402: profile file refused: " << error->message() << "\n";
      return false;
    }
    loaded_ = std::get<custom_profile>(result);
    profile_ = &loaded_.get();
    return true;
  }
  const profile* p = find_builtin_profile(name);
  if (p == nullptr) {
    err << "cia402: unknown profile '" << name << "' (built-in: " << builtin_profile_names()
        << ")\n";
    return false;
  }
  profile_ = p;
  return true;
}

void add_profile_options(CLI::App& cmd, std::string& name, std::string& file,
                         const std::string& name_help) {
  auto* by_name = cmd.add_option("--profile", name, name_help + ": " + builtin_profile_names())
                      ->type_name("NAME")
                      ->default_str("cia402");
  cmd.add_option("--profile-file", file, "a TOML profile file instead of a built-in")
      ->type_name("FILE")
      ->excludes(by_name);
}

}  // namespace cia402::cli
