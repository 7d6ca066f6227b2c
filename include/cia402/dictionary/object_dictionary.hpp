// The object dictionary (CiA 301 §7.4): a table of objects, each with sub-indices that carry a data
// type, an access type, a PDO-mappable flag, a default and value limits. The same table is what the
// slave serves over SDO and PDO and what the EDS writer (CiA 306) prints: one source of truth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cia402/data_type.hpp"
#include "cia402/sdo_abort.hpp"

namespace cia402::dictionary {

/// Access types as the EDS spells them (CiA 306 §4.6.3): ro, wo, rw, const.
enum class access : std::uint8_t { ro, wo, rw, constant };
const char* access_name(access a) noexcept;
constexpr bool readable(access a) noexcept { return a != access::wo; }
constexpr bool writable(access a) noexcept { return a == access::wo || a == access::rw; }

/// Object codes (CiA 301 §7.4.3): the EDS ObjectType values.
enum class object_code : std::uint8_t { var = 7, array = 8, record = 9 };

/// The EDS section an object is listed in (CiA 306 §4.6.2).
enum class object_category : std::uint8_t { mandatory, optional, manufacturer };

/// Where a value lives. `stored`: in the dictionary. `device`: the device behind the node answers
/// (dictionary::device::read / write), so the CiA 402 objects are the virtual drive's own.
enum class backing : std::uint8_t { stored, device };

/// One sub-index.
struct sub_entry {
  std::uint8_t sub = 0;
  std::string name;
  data_type type = data_type::unsigned8;
  access acc = access::ro;
  bool pdo_mappable = false;
  backing where = backing::stored;
  std::int64_t default_value = 0;
  bool plus_node_id = false;   ///< the default is node-ID + default_value ($NODEID+ in the EDS)
  std::string default_text;    ///< default of a string
  std::size_t capacity = 0;    ///< bytes a string may hold
  std::int64_t low = 0;        ///< value limits (inclusive) when has_limits
  std::int64_t high = 0;
  bool has_limits = false;
  /// The value came from a DCF's ParameterValue (CiA 306 §4.6.4: what the node is configured with),
  /// not from its DefaultValue (eds_reader.hpp).
  bool parameter_value = false;
};

struct object_entry {
  std::uint16_t index = 0;
  std::string name;
  object_code code = object_code::var;
  object_category category = object_category::optional;
  std::vector<sub_entry> subs;
};

/// A table of objects plus the present values of the stored ones.
class object_dictionary {
 public:
  struct slot {
    const object_entry* object = nullptr;
    const sub_entry* entry = nullptr;
    std::int64_t number = 0;
    std::string text;
  };

  /// Copies the table, sorts it by index, and sets every value to its default for `node_id`.
  object_dictionary(std::vector<object_entry> table, std::uint8_t node_id);
  object_dictionary(const object_dictionary&) = delete;
  object_dictionary& operator=(const object_dictionary&) = delete;

  /// The slot of index/sub, or nullptr; `abort` says which (0x06020000 or 0x06090011).
  slot* find(std::uint16_t index, std::uint8_t sub, sdo_abort& abort) noexcept;
  const slot* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  const object_entry* object(std::uint16_t index) const noexcept;

  /// Resets the values of objects in [first, last] to their defaults.
  void reset(std::uint16_t first, std::uint16_t last);

  const std::vector<object_entry>& table() const noexcept { return table_; }
  std::uint8_t node_id() const noexcept { return node_id_; }
  /// A stored number (the default of a missing entry: 0). For code that knows the entry exists.
  std::int64_t number(std::uint16_t index, std::uint8_t sub) const noexcept;
  void set_number(std::uint16_t index, std::uint8_t sub, std::int64_t v) noexcept;

  /// The default value of an entry for this node (with the node-ID added where the table says so).
  std::int64_t default_number(const sub_entry& e) const noexcept;

 private:
  std::vector<object_entry> table_;
  std::vector<slot> slots_;  // sorted by (index, sub)
  std::uint8_t node_id_;
};

/// Bytes -> value for a numeric type (sign-extended for signed types). The size must already match.
std::int64_t decode_value(data_type t, std::span<const std::uint8_t> bytes) noexcept;
/// Value -> its type_size(t) little-endian bytes.
void encode_value(data_type t, std::int64_t v, std::vector<std::uint8_t>& out);

}  // namespace cia402::dictionary
