#include "cia402/dictionary/error_history.hpp"

#include <string>
#include <vector>

#include "cia402/dictionary/object_builders.hpp"

namespace cia402::dictionary {

object_entry error_history_object(std::uint8_t depth) {
  std::vector<sub_entry> subs;
  subs.push_back(variable(0, "Number of errors", data_type::unsigned8, access::rw, 0));
  for (int i = 1; i <= depth; ++i) {
    subs.push_back(variable(static_cast<std::uint8_t>(i), "Standard error field " + std::to_string(i),
                            data_type::unsigned32, access::ro, 0));
  }
  return group(error_history_index, "Pre-defined error field", object_code::array, object_category::optional,
               std::move(subs));
}

void record_error(object_dictionary& od, std::uint16_t code, std::uint16_t info) noexcept {
  if (code == 0 || od.object(error_history_index) == nullptr) return;
  for (std::uint8_t sub = error_history_depth; sub > 1; --sub) {
    od.set_number(error_history_index, sub, od.number(error_history_index, static_cast<std::uint8_t>(sub - 1)));
  }
  od.set_number(error_history_index, 1, (std::int64_t{info} << 16) | code);
  const std::int64_t held = od.number(error_history_index, 0);
  if (held < error_history_depth) od.set_number(error_history_index, 0, held + 1);
}

sdo_abort write_error_history(object_dictionary& od, std::uint8_t sub, std::int64_t v) noexcept {
  if (sub != 0) return sdo_abort::read_only_object;  // the dictionary refuses these before
  if (v != 0) return sdo_abort::invalid_value;
  for (std::uint8_t s = 0; s <= error_history_depth; ++s) od.set_number(error_history_index, s, 0);
  return sdo_abort::none;
}

}  // namespace cia402::dictionary
