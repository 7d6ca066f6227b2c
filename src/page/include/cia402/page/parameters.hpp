// The page's parameter list and parameter files (docs/instrument-page.md, "Parameter list and
// parameter files"): what an entry of the drive is (CiA 301 §7.4: index, sub-index, data type,
// access, PDO mapping, limits, default; CiA 402's unit), and a neutral interface for the file a
// parameter set is saved to and loaded from. The page holds no file format of its own: `cia402 serve`
// hands it CiA 306's DCF writer and reader (canopen/306), for every drive alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace cia402::page {

/// One entry of the drive's object dictionary as the page lists it.
struct parameter_entry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string name;
  /// CiA 301 §7.1.6 data type index: 0x0002..0x0007 INTEGERn/UNSIGNEDn, 0x0009 VISIBLE_STRING,
  /// 0x0015 INTEGER64, 0x001B UNSIGNED64.
  std::uint16_t data_type = 0x0007;
  std::string access = "rw";  ///< "ro", "wo", "rw" or "const" (CiA 306 §4.6.3)
  bool pdo_mappable = false;
  std::optional<std::int64_t> low, high;      ///< the limits a write must keep; none: the type's
  std::optional<std::int64_t> default_number;  ///< a number's default
  std::string default_text;                    ///< a string's default
  std::string unit;                            ///< CiA 402's unit ("rpm"), empty for none
};

/// A value a parameter file gives: a number as decimal text, a string as itself.
struct parameter_value {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string value;
};

/// A parameter file that does not parse: its line (1-based; 0: the file as a whole) and why.
struct parameter_file_error {
  std::size_t line = 0;
  std::string reason;
};

/// The file a parameter set is kept in. `write`: every entry, with its present value where one was
/// read (a number as decimal text, a string as itself); the node-ID the file is for (0: none).
/// `read`: the values a file gives, in file order, or why it does not parse. Empty functions: the
/// page offers no parameter files.
struct parameter_file_format {
  std::string extension = "dcf";
  std::string media_type = "text/plain";
  std::function<std::string(const std::vector<parameter_entry>& entries,
                            const std::vector<std::optional<std::string>>& values, int node)>
      write;
  std::function<std::variant<std::vector<parameter_value>, parameter_file_error>(std::string_view text)> read;
};

}  // namespace cia402::page
