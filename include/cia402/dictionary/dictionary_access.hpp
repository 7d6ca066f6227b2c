// Object access with the rules of the dictionary: the object and sub-index exist, the access type
// allows it, the size fits the data type, the value keeps the type's and the entry's limits. What a
// value then does is the owner's: read_value / write_value. The CANopen node (slave.hpp) and the
// EtherCAT CoE server (ethercat/coe) reach objects through this one implementation, so a request
// refused on one bus is refused on the other with the same abort code.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/dictionary/object_access.hpp"

namespace cia402::dictionary {

class dictionary_access : public object_access {
 public:
  explicit dictionary_access(object_dictionary& od) noexcept : od_(&od) {}

  /// Local access with every rule the SDO server applies; values as int64 (strings refused).
  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& value);
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t value);
  /// The same rules on an entry found before: a PDO entry is bound to its slot once, when its mapping
  /// is configured, so a cycle reads and writes through these without looking the object up.
  sdo_abort read(const object_dictionary::slot& s, std::int64_t& value);
  sdo_abort write(object_dictionary::slot& s, std::int64_t value);

  sdo_abort check_download(std::uint16_t index, std::uint8_t sub, std::size_t size,
                           bool size_known) noexcept override;
  sdo_abort download(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                     bool size_indicated) noexcept override;
  sdo_abort upload(std::uint16_t index, std::uint8_t sub,
                   std::vector<std::uint8_t>& data) noexcept override;

 protected:
  ~dictionary_access() = default;
  /// The value of a readable numeric entry.
  virtual sdo_abort read_value(const object_dictionary::slot& s, std::int64_t& v) = 0;
  /// Takes a value that passed every dictionary rule; may still refuse it (its own checks).
  virtual sdo_abort write_value(object_dictionary::slot& s, std::int64_t v) = 0;

  object_dictionary& dictionary() noexcept { return *od_; }
  const object_dictionary& dictionary() const noexcept { return *od_; }

 private:
  object_dictionary* od_;
};

}  // namespace cia402::dictionary
