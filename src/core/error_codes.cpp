// The emergency error codes (CiA 301 table 21; CiA 402 / IEC 61800-7-201's device-profile codes).
#include "cia402/error_codes.hpp"

#include "cia402/drive.hpp"

namespace cia402 {
namespace {

// Ascending by code (checked below), so a lookup is a binary search.
constexpr error_code_description table[] = {
    {0x0000, "error reset or no error"},
    {0x1000, "generic error"},
    {0x2000, "current"},
    {0x2100, "current, device input side"},
    {0x2110, "short circuit or earth leakage (input)"},
    {0x2120, "earth leakage (input)"},
    {0x2130, "short circuit (input)"},
    {0x2200, "current inside the device"},
    {0x2211, "internal current no. 1"},
    {0x2212, "internal current no. 2"},
    {0x2213, "over-current in ramp function"},
    {0x2214, "over-current in the sequence"},
    {0x2220, "continuous over-current (device internal)"},
    {0x2230, "short circuit or earth leakage (device internal)"},
    {0x2240, "earth leakage (device internal)"},
    {0x2250, "short circuit (device internal)"},
    {0x2300, "current, device output side"},
    {0x2310, "continuous over-current"},
    {0x2311, "continuous over-current no. 1"},
    {0x2312, "continuous over-current no. 2"},
    {0x2320, "short circuit or earth leakage (motor side)"},
    {0x2330, "earth leakage (motor side)"},
    {0x2340, "short circuit (motor side)"},
    {0x3000, "voltage"},
    {0x3100, "mains voltage"},
    {0x3110, "mains over-voltage"},
    {0x3120, "mains under-voltage"},
    {0x3130, "phase failure"},
    {0x3140, "mains frequency"},
    {0x3200, "voltage inside the device"},
    {0x3210, "DC link over-voltage"},
    {0x3220, "DC link under-voltage"},
    {0x3230, "load error"},
    {0x3300, "output voltage"},
    {0x3310, "output over-voltage"},
    {0x3320, "armature circuit"},
    {0x3330, "field circuit"},
    {0x4000, "temperature"},
    {0x4100, "ambient temperature"},
    {0x4110, "excess ambient temperature"},
    {0x4120, "too low ambient temperature"},
    {0x4200, "device temperature"},
    {0x4210, "excess device temperature"},
    {0x4220, "too low device temperature"},
    {0x4300, "drive temperature"},
    {0x4310, "excess drive temperature"},
    {0x4320, "too low drive temperature"},
    {0x4400, "supply temperature"},
    {0x4410, "excess supply temperature"},
    {0x4420, "too low supply temperature"},
    {0x5000, "device hardware"},
    {0x5100, "supply"},
    {0x5110, "supply low voltage"},
    {0x5200, "control"},
    {0x5210, "measurement circuit"},
    {0x5220, "computing circuit"},
    {0x5300, "operating unit"},
    {0x5400, "power section"},
    {0x5410, "output stages"},
    {0x5420, "chopper"},
    {0x5430, "input stages"},
    {0x5500, "data storage"},
    {0x5510, "RAM"},
    {0x5520, "EPROM"},
    {0x5530, "EEPROM"},
    {0x6000, "device software"},
    {0x6010, "reset by watchdog"},
    {0x6100, "internal software"},
    {0x6200, "user software"},
    {0x6300, "data set"},
    {0x6310, "loss of parameters"},
    {0x6320, "parameter error"},
    {0x7000, "additional modules"},
    {0x7100, "power"},
    {0x7110, "brake chopper"},
    {0x7120, "motor"},
    {0x7121, "motor blocked"},
    {0x7122, "motor error or commutation malfunction"},
    {0x7123, "motor tilted"},
    {0x7200, "measurement circuit"},
    {0x7300, "sensor"},
    {0x7301, "tacho fault"},
    {0x7302, "tacho wrong polarity"},
    {0x7303, "resolver 1 fault"},
    {0x7304, "resolver 2 fault"},
    {0x7305, "incremental sensor 1 fault"},
    {0x7306, "incremental sensor 2 fault"},
    {0x7307, "incremental sensor 3 fault"},
    {0x7310, "speed"},
    {0x7320, "position"},
    {0x7400, "computation circuit"},
    {0x7500, "communication"},
    {0x7510, "serial interface no. 1"},
    {0x7520, "serial interface no. 2"},
    {0x7600, "data storage"},
    {0x8000, "monitoring"},
    {0x8100, "communication"},
    {0x8110, "CAN overrun (objects lost)"},
    {0x8120, "CAN in error passive mode"},
    {0x8130, "life guard error or heartbeat error"},
    {0x8140, "recovered from bus off"},
    {0x8150, "CAN-ID collision"},
    {0x8200, "protocol error"},
    {0x8210, "PDO not processed due to length error"},
    {0x8220, "PDO length exceeded"},
    {0x8230, "DAM MPDO not processed, destination object not available"},
    {0x8240, "unexpected SYNC data length"},
    {0x8250, "RPDO timeout"},
    {0x8300, "torque control"},
    {0x8311, "excess torque"},
    {0x8312, "difficult start up"},
    {0x8313, "standstill torque"},
    {0x8321, "insufficient torque"},
    {0x8331, "torque fault"},
    {0x8400, "velocity speed controller"},
    {0x8500, "position controller"},
    {0x8600, "positioning controller"},
    {0x8611, "following error"},
    {0x8612, "reference limit"},
    {0x8700, "sync controller"},
    {0x8800, "winding controller"},
    {0x9000, "external error"},
    {0xF000, "additional functions"},
    {0xF001, "deceleration"},
    {0xF002, "sub-synchronous run"},
    {0xF003, "stroke operation"},
    {0xF004, "control"},
    {0xFF00, "device specific"},
    // The project's drive raises this one for STO while torque is on (S14); other makers use 0xFF01
    // for something of their own, which the text says.
    {error_code::safe_torque_off, "device specific (the cia402 drive: safe torque off while torque was on)"},
};

constexpr std::size_t table_size = sizeof table / sizeof table[0];

constexpr bool ascending() noexcept {
  for (std::size_t i = 1; i < table_size; ++i) {
    if (table[i - 1].code >= table[i].code) return false;
  }
  return true;
}
static_assert(ascending(), "the error code table must be in ascending code order");

const error_code_description* find(std::uint16_t code) noexcept {
  std::size_t low = 0, high = table_size;
  while (low < high) {
    const std::size_t mid = low + (high - low) / 2;
    if (table[mid].code == code) return &table[mid];
    if (table[mid].code < code) low = mid + 1; else high = mid;
  }
  return nullptr;
}

}  // namespace

std::size_t error_code_count() noexcept { return table_size; }

const error_code_description& error_code_entry(std::size_t i) noexcept {
  return table[i < table_size ? i : table_size - 1];
}

const char* error_code_text(std::uint16_t code) noexcept {
  if (const auto* e = find(code)) return e->text;
  // 0x0000 is "no error", not the class of 0x0001..0x0FFF: those codes are undefined.
  if ((code & 0xFF00u) != 0) {
    if (const auto* e = find(static_cast<std::uint16_t>(code & 0xFF00u))) return e->text;
  }
  if ((code & 0xF000u) != 0) {
    if (const auto* e = find(static_cast<std::uint16_t>(code & 0xF000u))) return e->text;
  }
  return "unknown error code";
}

}  // namespace cia402
