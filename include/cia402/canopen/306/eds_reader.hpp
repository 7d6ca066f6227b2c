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
//
// A peer's file is not trusted. Every LowLimit, HighLimit, DefaultValue and ParameterValue (the one
// taken and the one left) must be a value of its entry's data type; a "$NODEID+X" one must be so with
// the file's NodeID added, or with any node-ID 1..127 when the file names none. A section named
// twice, in any spelling ("[60E3sub2]" and "[60E3sub02]"), is refused with both lines. So what
// write_dcf writes of what read_eds gave, read_eds reads back to the same entries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"

namespace cia402::canopen {

struct eds_contents {
  std::vector<dictionary::object_entry> objects;  ///< in index order
  std::uint8_t node_id = 0;           ///< [DeviceComissioning] NodeID, 0 when the file has none
};

struct eds_error {
  std::size_t line = 0;  ///< 1-based; 0 when the file as a whole is at fault
  std::string reason;
};

std::variant<eds_contents, eds_error> read_eds(std::string_view text);

/// An entry's number on node `node_id`: its default value, plus the node-ID when it is "$NODEID+X";
/// nothing when that is not a value of the entry's data type (a file read for one node and used for
/// another may not fit). The sum is checked: it never overflows.
std::optional<std::int64_t> value_for_node(const dictionary::sub_entry& e, int node_id);

}  // namespace cia402::canopen
