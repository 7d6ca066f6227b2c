// Damaged profile files: whatever a byte-level mutation of a good file does, the loader returns a
// sound profile or a refusal with a place, and never crashes or hands over a profile check_profile
// would reject.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <variant>

#include "cia402/profile_file.hpp"

namespace cia402 {
namespace {

std::string mutate(std::string text, std::mt19937& rng) {
  static constexpr char alphabet[] = "[]=\"#,.{}0123456789xabcdefstn_ \n";
  std::uniform_int_distribution<std::size_t> at(0, text.size() - 1);
  std::uniform_int_distribution<int> kind(0, 3);
  const int edits = 1 + static_cast<int>(rng() % 3);
  for (int e = 0; e < edits && !text.empty(); ++e) {
    const std::size_t i = at(rng) % text.size();
    switch (kind(rng)) {
      case 0:
        text.erase(i, 1);
        break;
      case 1:
        text[i] = alphabet[rng() % (sizeof(alphabet) - 1)];
        break;
      case 2:
        text.insert(i, 1, alphabet[rng() % (sizeof(alphabet) - 1)]);
        break;
      default: {  // repeat the line at i
        const std::size_t start =
            text.rfind('\n', i) == std::string::npos ? 0 : text.rfind('\n', i) + 1;
        const std::size_t end = text.find('\n', i);
        if (end != std::string::npos) text.insert(start, text.substr(start, end - start + 1));
      }
    }
  }
  return text;
}

TEST(profile_file_mutations, damaged_dumps_load_sound_or_are_refused_with_a_place) {
  std::mt19937 rng(40266u);
  int refused = 0;
  int loaded = 0;
  for (std::size_t p = 0; p < builtin_profile_count(); ++p) {
    const std::string good = dump_profile_toml(builtin_profile(p));
    const int lines = static_cast<int>(std::count(good.begin(), good.end(), '\n'));
    for (int i = 0; i < 400; ++i) {
      const std::string text = mutate(good, rng);
      profile_load_result r = load_profile_toml(text, "mutated.toml");
      if (const auto* e = std::get_if<profile_file_error>(&r)) {
        ++refused;
        EXPECT_FALSE(e->reason.empty());
        EXPECT_GE(e->line, 0);
        EXPECT_LE(e->line, lines + 4) << e->message();
      } else {
        ++loaded;
        int row = -1;
        EXPECT_EQ(check_profile(std::get<custom_profile>(r).get(), row), nullptr) << text;
      }
    }
  }
  // Both outcomes must occur, or the mutations tested nothing.
  EXPECT_GT(refused, 100);
  EXPECT_GT(loaded, 10);
}

}  // namespace
}  // namespace cia402
