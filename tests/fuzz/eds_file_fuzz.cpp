// EDS and DCF files (canopen/306): any bytes are refused with a line and a reason, or give entries
// whose every number is a value of its type (with the file's node added to a $NODEID+X one, or any
// node 1..127 when the file names none), and what write_dcf writes of them read_eds reads back to the
// same entries, and writes again to the same text (the round trip of issue 42: a saved parameter file
// always loads).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <variant>

#include "../canopen/eds_round_trip.hpp"
#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/306/eds_reader.hpp"

namespace {

using namespace cia402;
using namespace cia402::canopen;
using namespace cia402::dictionary;

[[noreturn]] void fail(const char* what, const std::string& a = {}, const std::string& b = {}) {
  std::fprintf(stderr, "eds_file_fuzz: %s\n--- first\n%s\n--- second\n%s\n", what, a.c_str(), b.c_str());
  std::abort();
}

bool in_type(data_type t, std::int64_t v) { return v >= type_min(t) && v <= type_max(t); }

// The reader's promise on what it accepted: numbers of their types, sums that fit.
void check_types(const eds_contents& c) {
  for (const object_entry& o : c.objects) {
    for (const sub_entry& e : o.subs) {
      if (e.type == data_type::visible_string) {
        if (e.has_limits) fail("a string with limits");
        continue;
      }
      if (!in_type(e.type, e.default_value)) fail("a value outside its type");
      if (e.has_limits && (!in_type(e.type, e.low) || !in_type(e.type, e.high))) fail("a limit outside its type");
      if (!e.plus_node_id) continue;
      const bool fits = c.node_id != 0 ? value_for_node(e, c.node_id).has_value()
                                       : value_for_node(e, 1).has_value() && value_for_node(e, 127).has_value();
      if (!fits) fail("a $NODEID+X that leaves its type");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto first = read_eds(text);
  if (const auto* e = std::get_if<eds_error>(&first)) {
    if (e->reason.empty()) fail("a refusal without a reason");
    return 0;
  }
  const eds_contents& accepted = std::get<eds_contents>(first);
  check_types(accepted);
  const std::string dcf = dcf_of(accepted);
  auto second = read_eds(dcf);
  if (const auto* e = std::get_if<eds_error>(&second)) {
    fail(("the written DCF is refused at line " + std::to_string(e->line) + ": " + e->reason).c_str(), dcf);
  }
  const eds_contents& again = std::get<eds_contents>(second);
  if (entry_fields(again) != entry_fields(accepted)) {
    fail("the DCF reads back to other entries", entry_fields(accepted), entry_fields(again));
  }
  if (dcf_of(again) != dcf) fail("the DCF writes again to another text", dcf, dcf_of(again));
  return 0;
}
