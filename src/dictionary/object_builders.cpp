#include "cia402/dictionary/object_builders.hpp"

#include <utility>

namespace cia402::dictionary {

sub_entry variable(std::uint8_t sub, std::string name, data_type t, access a, std::int64_t default_value) {
  sub_entry e;
  e.sub = sub;
  e.name = std::move(name);
  e.type = t;
  e.acc = a;
  e.default_value = default_value;
  return e;
}

sub_entry text(std::uint8_t sub, std::string name, access a, std::string default_text, std::size_t capacity) {
  sub_entry e = variable(sub, std::move(name), data_type::visible_string, a);
  e.default_text = std::move(default_text);
  e.capacity = capacity;
  return e;
}

sub_entry mappable(sub_entry e) {
  e.pdo_mappable = true;
  return e;
}

sub_entry on_device(sub_entry e) {
  e.where = backing::device;
  return e;
}

sub_entry plus_node_id(sub_entry e) {
  e.plus_node_id = true;
  return e;
}

sub_entry limited(sub_entry e, std::int64_t low, std::int64_t high) {
  e.has_limits = true;
  e.low = low;
  e.high = high;
  return e;
}

object_entry single(std::uint16_t index, object_category c, sub_entry e) {
  object_entry o;
  o.index = index;
  o.name = e.name;
  o.code = object_code::var;
  o.category = c;
  o.subs.push_back(std::move(e));
  return o;
}

object_entry group(std::uint16_t index, std::string name, object_code code, object_category c,
                   std::vector<sub_entry> subs) {
  object_entry o;
  o.index = index;
  o.name = std::move(name);
  o.code = code;
  o.category = c;
  o.subs = std::move(subs);
  return o;
}

object_entry pdo_mapping(std::uint16_t index, std::string name, const pdo_map& defaults, std::uint8_t capacity) {
  std::vector<sub_entry> subs;
  const std::uint8_t count = defaults.count < capacity ? defaults.count : capacity;
  subs.push_back(limited(variable(0, "Number of mapped objects", data_type::unsigned8, access::rw, count), 0, capacity));
  for (std::uint8_t i = 1; i <= capacity; ++i) {
    const std::uint32_t word = i <= count ? defaults.entries[i - 1u].word() : 0;
    subs.push_back(variable(i, "Mapped object " + std::to_string(i), data_type::unsigned32, access::rw, word));
  }
  return group(index, std::move(name), object_code::record, object_category::optional, std::move(subs));
}

}  // namespace cia402::dictionary
