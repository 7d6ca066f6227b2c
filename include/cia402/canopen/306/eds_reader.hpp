// Reading an EDS or DCF (CiA 306): the objects a device describes, as the node's own table type
// (object_dictionary.hpp's object_entry), so a node known from its file is known as the project's
// node knows itself: names, data types, access, PDO mapping and default values (the mapping and
// COB-IDs of its PDOs at power-up among them). A DCF's ParameterValue is taken over DefaultValue:
// it is what the node was configured with.
//
// What is read: the object sections "[XXXX]" and "[XXXXsubN]" (hexadecimal; keys in any case) of
// VAR, ARRAY and RECORD objects, with CompactSubObj; values decimal, 0x-hexadecimal or 0-octal,
// "$NODEID+X" and "X+$NODEID" (plus_node_id); [DeviceComissioning] NodeID. Entries of a data type the
// dictionary has no type for (REAL32, OCTET_STRING, DOMAIN, ...) and DOMAIN / DEFTYPE / DEFSTRUCT
// objects are left out. A file that does not parse is refused with its line and reason, and gives
// nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cia402/canopen/301/object_dictionary.hpp"

namespace cia402::canopen {

struct eds_contents {
  std::vector<object_entry> objects;  ///< in index order
  std::uint8_t node_id = 0;           ///< [DeviceComissioning] NodeID, 0 when the file has none
};

struct eds_error {
  std::size_t line = 0;  ///< 1-based; 0 when the file as a whole is at fault
  std::string reason;
};

std::variant<eds_contents, eds_error> read_eds(std::string_view text);

}  // namespace cia402::canopen
