#include "cli/parameter_file.hpp"

#include <charconv>
#include <ctime>
#include <map>
#include <sstream>
#include <string>

#include "cia402/canopen/306/eds.hpp"
#include "cia402/canopen/306/eds_reader.hpp"
#include "cia402/support/text.hpp"

namespace cia402::cli {
namespace {

// A text as one line of the file: a drive's text (its device name, 0x1008) is a peer's and may hold
// anything; a line break in it would start a line of its own.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r' || c == '\0') c = ' ';
  }
  return text;
}

dictionary::access access_of(const std::string& a) {
  if (a == "rw") return dictionary::access::rw;
  if (a == "wo") return dictionary::access::wo;
  if (a == "const") return dictionary::access::constant;
  return dictionary::access::ro;
}

// The page's entries as the dictionary's objects: one VAR where an index has only sub-index 0, else
// a RECORD named by its sub-index 0 (CiA 301 §7.4.3).
std::vector<dictionary::object_entry> objects_of(const std::vector<page::parameter_entry>& entries) {
  std::map<std::uint16_t, std::vector<const page::parameter_entry*>> by_index;
  for (const page::parameter_entry& e : entries) by_index[e.index].push_back(&e);
  std::vector<dictionary::object_entry> out;
  for (const auto& [index, subs] : by_index) {
    dictionary::object_entry o;
    o.index = index;
    o.name = one_line(subs.front()->name);
    const bool var = subs.size() == 1 && subs.front()->sub == 0;
    o.code = var ? dictionary::object_code::var : dictionary::object_code::record;
    for (const page::parameter_entry* e : subs) {
      dictionary::sub_entry s;
      s.sub = e->sub;
      s.name = !var && e->sub == 0 ? "Highest sub-index supported" : one_line(e->name);
      s.type = static_cast<data_type>(e->data_type);
      s.acc = access_of(e->access);
      s.pdo_mappable = e->pdo_mappable;
      s.default_value = e->default_number.value_or(0);
      s.default_text = one_line(e->default_text);
      if (e->low || e->high) {
        s.has_limits = true;
        s.low = e->low.value_or(type_min(s.type));
        s.high = e->high.value_or(type_max(s.type));
      }
      o.subs.push_back(std::move(s));
    }
    out.push_back(std::move(o));
  }
  return out;
}

canopen::eds_info file_info(int node) {
  canopen::eds_info info;
  info.file_name = "cia402-parameters.dcf";
  info.description = "parameter set saved by cia402 serve";
  info.created_by = "cia402 serve";
  const std::time_t now = std::time(nullptr);
  std::tm t{};
  gmtime_r(&now, &t);
  char date[16], time[16];
  std::strftime(date, sizeof date, "%m-%d-%Y", &t);
  std::strftime(time, sizeof time, "%I:%M%p", &t);
  info.date = date;
  info.time = time;
  info.node_id = node >= 1 && node <= 127 ? static_cast<std::uint8_t>(node) : 0;
  return info;
}

std::string write_file(const std::vector<page::parameter_entry>& entries,
                       const std::vector<std::optional<std::string>>& values, int node) {
  const std::vector<dictionary::object_entry> objects = objects_of(entries);
  canopen::dcf_values given;
  for (std::size_t i = 0; i < entries.size() && i < values.size(); ++i) {
    if (!values[i]) continue;
    const page::parameter_entry& e = entries[i];
    if (e.data_type == static_cast<std::uint16_t>(data_type::visible_string)) {
      given[{e.index, e.sub}] = one_line(*values[i]);
      continue;
    }
    std::int64_t number = 0;
    const std::string& text = *values[i];
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
    if (ec != std::errc() || end != text.data() + text.size()) continue;  // not a number: no value
    dictionary::sub_entry s;
    s.type = static_cast<data_type>(e.data_type);
    // A value its type cannot hold (a peer's answer) would make a file the reader refuses: no value.
    if (number < type_min(s.type) || number > type_max(s.type)) continue;
    given[{e.index, e.sub}] = canopen::dcf_value_text(s, number);
  }
  std::ostringstream out;
  canopen::write_dcf(objects, given, file_info(node), out);
  return out.str();
}

std::variant<std::vector<page::parameter_value>, page::parameter_file_error> read_file(std::string_view text) {
  auto parsed = canopen::read_eds(text);
  if (const auto* bad = std::get_if<canopen::eds_error>(&parsed)) {
    return page::parameter_file_error{bad->line, bad->reason};
  }
  const canopen::eds_contents& dcf = std::get<canopen::eds_contents>(parsed);
  std::vector<page::parameter_value> out;
  for (const dictionary::object_entry& o : dcf.objects) {
    for (const dictionary::sub_entry& s : o.subs) {
      if (!s.parameter_value) continue;
      if (s.type == data_type::visible_string) {
        out.push_back({o.index, s.sub, s.default_text});
        continue;
      }
      // read_eds has checked $NODEID+X against the type for the file's node; checked again here,
      // so no sum can overflow whatever the reader lets through.
      const auto number = canopen::value_for_node(s, dcf.node_id);
      if (!number) {
        return page::parameter_file_error{0, support::hex(o.index, 4) + ":" + std::to_string(s.sub) +
                                                 ": its value is outside its data type for node " +
                                                 std::to_string(dcf.node_id)};
      }
      out.push_back({o.index, s.sub, std::to_string(*number)});
    }
  }
  return out;
}

}  // namespace

page::parameter_file_format dcf_parameter_file() {
  page::parameter_file_format f;
  f.extension = "dcf";
  f.media_type = "text/plain";
  f.write = write_file;
  f.read = read_file;
  return f;
}

std::vector<page::parameter_entry> parameter_entries(const std::vector<dictionary::object_entry>& objects,
                                                     int node_id) {
  std::vector<page::parameter_entry> out;
  for (const dictionary::object_entry& o : objects) {
    if (o.index == 0x1021) continue;  // the EDS itself (store EDS): a file of 30 KiB, not a parameter
    for (const dictionary::sub_entry& s : o.subs) {
      page::parameter_entry e;
      e.index = o.index;
      e.sub = s.sub;
      e.name = o.code == dictionary::object_code::var || s.sub == 0 ? o.name : s.name;
      e.data_type = static_cast<std::uint16_t>(s.type);
      e.access = dictionary::access_name(s.acc);
      e.pdo_mappable = s.pdo_mappable;
      if (s.has_limits) {
        e.low = s.low;
        e.high = s.high;
      }
      if (s.type == data_type::visible_string) {
        e.default_text = s.default_text;
      } else {
        // Nothing when "$NODEID+X" does not fit its type on this node (an EDS written for another).
        e.default_number = canopen::value_for_node(s, node_id);
      }
      out.push_back(std::move(e));
    }
  }
  return out;
}

std::vector<page::parameter_entry> parameter_entries(const std::vector<ethercat::ecat_object_description>& objects) {
  const auto shown = [](std::uint16_t t) {
    switch (static_cast<data_type>(t)) {
      case data_type::boolean:
      case data_type::integer8:
      case data_type::integer16:
      case data_type::integer32:
      case data_type::unsigned8:
      case data_type::unsigned16:
      case data_type::unsigned32:
      case data_type::visible_string:
      case data_type::integer64:
      case data_type::unsigned64: return true;
    }
    return false;
  };
  constexpr std::uint8_t var = 7;
  std::vector<page::parameter_entry> out;
  for (const ethercat::ecat_object_description& o : objects) {
    for (const ethercat::ecat_entry_description& s : o.entries) {
      if (!shown(s.data_type)) continue;
      page::parameter_entry e;
      e.index = o.index;
      e.sub = s.sub;
      e.name = o.object_code == var || s.sub == 0 ? o.name : s.name;
      e.data_type = s.data_type;
      // ETG.1000.6 object access: bits 0..2 read, 3..5 write (PRE-OP, SAFE-OP, OP), 6..7 PDO mapping.
      const bool read = (s.access & 0x0007) != 0;
      const bool write = (s.access & 0x0038) != 0;
      e.access = read && write ? "rw" : write ? "wo" : "ro";
      e.pdo_mappable = (s.access & 0x00C0) != 0;
      out.push_back(std::move(e));
    }
  }
  return out;
}

}  // namespace cia402::cli
