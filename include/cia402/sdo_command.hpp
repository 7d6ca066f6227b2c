// The command specifiers of CiA 301's SDO protocol (§7.2.4.3): the top three bits of an SDO's first
// byte. One list for every layer that reads or writes SDOs: the CANopen SDO server, the bus
// monitor, and CoE, whose SDO frames are CiA 301's (ETG.1000.6 §5.6.2). Part of the core, beside
// the abort codes (sdo_abort.hpp).
#pragma once

#include <cstdint>

namespace cia402::sdo_command_specifier {

/// The client's command specifiers (ccs), the server's (scs), and Abort SDO Transfer, the same from
/// either side.
inline constexpr std::uint8_t ccs_download_segment = 0, ccs_initiate_download = 1, ccs_initiate_upload = 2,
                              ccs_upload_segment = 3, ccs_block_upload = 5, ccs_block_download = 6;
inline constexpr std::uint8_t scs_upload_segment = 0, scs_download_segment = 1, scs_initiate_upload = 2,
                              scs_initiate_download = 3, scs_block_download = 5, scs_block_upload = 6;
inline constexpr std::uint8_t cs_abort = 4;

}  // namespace cia402::sdo_command_specifier
