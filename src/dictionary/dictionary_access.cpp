#include "cia402/dictionary/dictionary_access.hpp"

#include <algorithm>

namespace cia402::dictionary {

sdo_abort dictionary_access::read(std::uint16_t index, std::uint8_t sub, std::int64_t& value) {
  sdo_abort a = sdo_abort::none;
  const object_dictionary::slot* s = od_->find(index, sub, a);
  if (s == nullptr) return a;
  return read(*s, value);
}

sdo_abort dictionary_access::write(std::uint16_t index, std::uint8_t sub, std::int64_t value) {
  sdo_abort a = sdo_abort::none;
  object_dictionary::slot* s = od_->find(index, sub, a);
  if (s == nullptr) return a;
  return write(*s, value);
}

sdo_abort dictionary_access::read(const object_dictionary::slot& s, std::int64_t& value) {
  if (!readable(s.entry->acc)) return sdo_abort::write_only_object;
  if (s.entry->type == data_type::visible_string) return sdo_abort::unsupported_access;
  return read_value(s, value);
}

sdo_abort dictionary_access::write(object_dictionary::slot& s, std::int64_t value) {
  const sub_entry& e = *s.entry;
  if (!writable(e.acc)) return sdo_abort::read_only_object;
  if (e.type == data_type::visible_string) return sdo_abort::unsupported_access;
  if (value < type_min(e.type)) return sdo_abort::value_too_low;
  if (value > type_max(e.type)) return sdo_abort::value_too_high;
  if (e.has_limits && value < e.low) return sdo_abort::value_too_low;
  if (e.has_limits && value > e.high) return sdo_abort::value_too_high;
  return write_value(s, value);
}

sdo_abort dictionary_access::check_download(std::uint16_t index, std::uint8_t sub, std::size_t size,
                                            bool size_known) noexcept {
  sdo_abort a = sdo_abort::none;
  const object_dictionary::slot* s = od_->find(index, sub, a);
  if (s == nullptr) return a;
  const sub_entry& e = *s->entry;
  if (!writable(e.acc)) return sdo_abort::read_only_object;
  if (!size_known) return sdo_abort::none;
  if (e.type == data_type::visible_string) {
    return size > e.capacity ? sdo_abort::data_type_length_too_high : sdo_abort::none;
  }
  if (size > type_size(e.type)) return sdo_abort::data_type_length_too_high;
  if (size < type_size(e.type)) return sdo_abort::data_type_length_too_low;
  return sdo_abort::none;
}

sdo_abort dictionary_access::download(std::uint16_t index, std::uint8_t sub,
                                      std::span<const std::uint8_t> data, bool size_indicated) noexcept {
  sdo_abort a = sdo_abort::none;
  object_dictionary::slot* s = od_->find(index, sub, a);
  if (s == nullptr) return a;
  const sub_entry& e = *s->entry;
  if (e.type == data_type::visible_string) {
    if (!size_indicated) {  // an expedited download without size: up to the first NUL
      data = data.first(static_cast<std::size_t>(std::find(data.begin(), data.end(), 0) - data.begin()));
    }
    a = check_download(index, sub, data.size(), true);
    if (a != sdo_abort::none) return a;
    s->text.assign(data.begin(), data.end());
    return sdo_abort::none;
  }
  if (!size_indicated && data.size() > type_size(e.type)) data = data.first(type_size(e.type));
  a = check_download(index, sub, data.size(), true);
  if (a != sdo_abort::none) return a;
  // The value's checks are write()'s: the type's range (a BOOLEAN above 1) and the entry's limits,
  // in one place for an SDO download, a PDO's mapped entry and a local write alike.
  return write(*s, decode_value(e.type, data));
}

sdo_abort dictionary_access::upload(std::uint16_t index, std::uint8_t sub,
                                    std::vector<std::uint8_t>& data) noexcept {
  sdo_abort a = sdo_abort::none;
  const object_dictionary::slot* s = od_->find(index, sub, a);
  if (s == nullptr) return a;
  if (!readable(s->entry->acc)) return sdo_abort::write_only_object;
  if (s->entry->type == data_type::visible_string) {
    data.assign(s->text.begin(), s->text.end());
    return sdo_abort::none;
  }
  std::int64_t v = 0;
  a = read_value(*s, v);
  if (a != sdo_abort::none) return a;
  encode_value(s->entry->type, v, data);
  return sdo_abort::none;
}

}  // namespace cia402::dictionary
