#include "cia402/dictionary/object_dictionary.hpp"

#include <algorithm>


namespace cia402::dictionary {

const char* access_name(access a) noexcept {
  switch (a) {
    case access::ro: return "ro";
    case access::wo: return "wo";
    case access::rw: return "rw";
    case access::constant: return "const";
  }
  return "ro";
}

std::int64_t decode_value(data_type t, std::span<const std::uint8_t> bytes) noexcept {
  const unsigned n = type_size(t);
  if (n == 0 || bytes.size() < n) return 0;
  const std::uint64_t raw = get_le(bytes.data(), n);
  if (type_is_signed(t) && n < 8) {
    const std::uint64_t sign = 1ull << (8 * n - 1);
    return static_cast<std::int64_t>((raw ^ sign) - sign);
  }
  return static_cast<std::int64_t>(raw);
}

void encode_value(data_type t, std::int64_t v, std::vector<std::uint8_t>& out) {
  const unsigned n = type_size(t);
  out.resize(n);
  put_le(out.data(), static_cast<std::uint64_t>(v), n);
}

object_dictionary::object_dictionary(std::vector<object_entry> table, std::uint8_t node_id)
    : table_(std::move(table)), node_id_(node_id) {
  std::sort(table_.begin(), table_.end(),
            [](const object_entry& a, const object_entry& b) { return a.index < b.index; });
  for (object_entry& o : table_) {
    std::sort(o.subs.begin(), o.subs.end(),
              [](const sub_entry& a, const sub_entry& b) { return a.sub < b.sub; });
  }
  for (const object_entry& o : table_) {
    for (const sub_entry& e : o.subs) slots_.push_back(slot{&o, &e, default_number(e), e.default_text});
  }
}

std::int64_t object_dictionary::default_number(const sub_entry& e) const noexcept {
  return e.plus_node_id ? e.default_value + node_id_ : e.default_value;
}

object_dictionary::slot* object_dictionary::find(std::uint16_t index, std::uint8_t sub,
                                                 sdo_abort& abort) noexcept {
  const auto key = [](const slot& s) {
    return (static_cast<std::uint32_t>(s.object->index) << 8) | s.entry->sub;
  };
  const std::uint32_t want = (static_cast<std::uint32_t>(index) << 8) | sub;
  auto it = std::lower_bound(slots_.begin(), slots_.end(), want,
                             [&](const slot& s, std::uint32_t k) { return key(s) < k; });
  if (it != slots_.end() && key(*it) == want) {
    abort = sdo_abort::none;
    return &*it;
  }
  abort = object(index) != nullptr ? sdo_abort::sub_index_does_not_exist
                                   : sdo_abort::object_does_not_exist;
  return nullptr;
}

const object_dictionary::slot* object_dictionary::find(std::uint16_t index,
                                                       std::uint8_t sub) const noexcept {
  sdo_abort ignored;
  return const_cast<object_dictionary*>(this)->find(index, sub, ignored);
}

const object_entry* object_dictionary::object(std::uint16_t index) const noexcept {
  auto it = std::lower_bound(table_.begin(), table_.end(), index,
                             [](const object_entry& o, std::uint16_t i) { return o.index < i; });
  return it != table_.end() && it->index == index ? &*it : nullptr;
}

void object_dictionary::reset(std::uint16_t first, std::uint16_t last) {
  for (slot& s : slots_) {
    if (s.object->index >= first && s.object->index <= last) {
      s.number = default_number(*s.entry);
      s.text = s.entry->default_text;
    }
  }
}

std::int64_t object_dictionary::number(std::uint16_t index, std::uint8_t sub) const noexcept {
  const slot* s = find(index, sub);
  return s != nullptr ? s->number : 0;
}

void object_dictionary::set_number(std::uint16_t index, std::uint8_t sub, std::int64_t v) noexcept {
  sdo_abort ignored;
  if (slot* s = find(index, sub, ignored)) s->number = v;
}

}  // namespace cia402::dictionary
