// The round trip of an EDS read by read_eds (306/eds_reader.hpp): every field of what it read as one
// text, and what write_dcf writes of it. Shared by eds_reader_test.cpp and the fuzz target
// tests/fuzz/eds_file_fuzz.cpp, which hold the same promise: the DCF reads back to the same entries.
#pragma once

#include <sstream>
#include <string>

#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/306/eds_reader.hpp"

namespace cia402::canopen {

// Every field of every entry, one line each, so two readings compare as texts (and a mismatch shows).
inline std::string entry_fields(const eds_contents& c) {
  std::ostringstream out;
  out << "node " << int{c.node_id} << "\n";
  for (const dictionary::object_entry& o : c.objects) {
    out << std::hex << o.index << std::dec << " '" << o.name << "' code " << int(o.code) << " category "
        << int(o.category) << "\n";
    for (const dictionary::sub_entry& e : o.subs) {
      out << "  sub " << int{e.sub} << " '" << e.name << "' type " << int(e.type) << " acc " << int(e.acc)
          << " pdo " << e.pdo_mappable << " where " << int(e.where) << " value " << e.default_value
          << " node+ " << e.plus_node_id << " text '" << e.default_text << "' capacity " << e.capacity
          << " limits " << e.has_limits << " " << e.low << ".." << e.high << " parameter "
          << e.parameter_value << "\n";
    }
  }
  return out.str();
}

// What write_dcf writes of a file read_eds gave: its entries, each ParameterValue again as one.
inline std::string dcf_of(const eds_contents& c) {
  dcf_values values;
  for (const dictionary::object_entry& o : c.objects) {
    for (const dictionary::sub_entry& e : o.subs) {
      if (e.parameter_value) values[{o.index, e.sub}] = dcf_entry_text(e);
    }
  }
  eds_info info;
  info.node_id = c.node_id;
  std::ostringstream out;
  write_dcf(c.objects, values, info, out);
  return out.str();
}

}  // namespace cia402::canopen
