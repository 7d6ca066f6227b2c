// Decoding the page's sample batches (src/page/sample_ring.hpp) in the tests: each sample's
// number, time and values back from the run-length coded columns.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cia402::page::testing {

struct decoded_sample {
  std::uint64_t number = 0;
  std::uint64_t time_us = 0;
  std::map<std::string, std::optional<std::int64_t>> values;
};

inline std::vector<decoded_sample> decode_batch(const nlohmann::json& b) {
  const std::uint64_t from = b.at("from").get<std::uint64_t>();
  const std::size_t n = b.at("n").get<std::size_t>();
  std::vector<decoded_sample> out(n);
  std::uint64_t t = b.at("t0").get<std::uint64_t>();
  std::size_t i = 0;
  if (n > 0) out[i++].time_us = t;
  const nlohmann::json& dt = b.at("dt");
  for (std::size_t k = 0; k + 1 < dt.size(); k += 2) {
    for (std::uint64_t c = 0; c < dt[k + 1].get<std::uint64_t>() && i < n; ++c) {
      t += dt[k].get<std::uint64_t>();
      out[i++].time_us = t;
    }
  }
  for (std::size_t q = 0; q < n; ++q) out[q].number = from + q;
  for (const auto& [name, runs] : b.at("columns").items()) {
    std::size_t at = 0;
    for (std::size_t k = 0; k + 1 < runs.size(); k += 2) {
      const std::optional<std::int64_t> v =
          runs[k].is_null() ? std::nullopt : std::optional<std::int64_t>(runs[k].get<std::int64_t>());
      for (std::uint64_t c = 0; c < runs[k + 1].get<std::uint64_t>() && at < n; ++c) out[at++].values[name] = v;
    }
  }
  return out;
}

}  // namespace cia402::page::testing
