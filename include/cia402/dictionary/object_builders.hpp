// Short ways to write a dictionary's entries (object_dictionary.hpp), for the tables a node, a
// device or a CoE slave serves: a variable and its decorations, a string, an object of one entry or
// of several, and a PDO mapping object (CiA 301 §7.5.2.36 / .38: sub-index 0 the count, then the
// entries) with its defaults from the one table of default PDOs (cia402/pdo_maps.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/pdo_maps.hpp"

namespace cia402::dictionary {

/// A numeric entry: sub-index, name, type, access, default.
sub_entry variable(std::uint8_t sub, std::string name, data_type t, access a, std::int64_t default_value = 0);
/// A VISIBLE_STRING entry of at most `capacity` bytes (0: as long as its default, for a constant).
sub_entry text(std::uint8_t sub, std::string name, access a, std::string default_text, std::size_t capacity);
sub_entry mappable(sub_entry e);
/// The value is the device's (dictionary::device::read / write), not stored in the dictionary.
sub_entry on_device(sub_entry e);
/// The default is node-ID + default ($NODEID+ in an EDS).
sub_entry plus_node_id(sub_entry e);
/// A write must keep [low, high] (narrower than the type).
sub_entry limited(sub_entry e, std::int64_t low, std::int64_t high);

/// A VAR object of one entry, named as the entry.
object_entry single(std::uint16_t index, object_category c, sub_entry e);
/// An ARRAY or RECORD object.
object_entry group(std::uint16_t index, std::string name, object_code code, object_category c,
                   std::vector<sub_entry> subs);
/// A PDO mapping object of `capacity` entries (rw UNSIGNED32), sub-index 0 limited to `capacity`,
/// holding `defaults` as it starts.
object_entry pdo_mapping(std::uint16_t index, std::string name, const pdo_map& defaults, std::uint8_t capacity);

}  // namespace cia402::dictionary
