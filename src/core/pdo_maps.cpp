#include "cia402/pdo_maps.hpp"

#include "cia402/objects.hpp"

namespace cia402 {

sdo_abort check_pdo_map(const pdo_map& m, bool receive, pdo_padding padding) noexcept {
  if (m.count > max_default_pdo_entries) return sdo_abort::cannot_map_to_pdo;
  for (std::size_t i = 0; i < m.count; ++i) {
    const pdo_mapping_entry& e = m.entries[i];
    if (is_pdo_padding(e.index, padding)) {
      if (pdo_padding_bits(e, padding) == 0) return sdo_abort::cannot_map_to_pdo;
      continue;
    }
    const object_description* o = find_drive_object(e.index, e.sub);
    if (o == nullptr) {
      return find_drive_object(e.index, 0) != nullptr ? sdo_abort::sub_index_does_not_exist
                                                      : sdo_abort::object_does_not_exist;
    }
    const bool direction = receive ? o->access != object_access::read_only : o->access != object_access::write_only;
    if (!o->pdo_mappable || !direction || e.bits != type_size(o->type) * 8) return sdo_abort::cannot_map_to_pdo;
  }
  return sdo_abort::none;
}

}  // namespace cia402
