// The page's parameter files as `cia402 serve` gives them (page/parameters.hpp): CiA 306 device
// configuration files, written by canopen/306's write_dcf and read by its read_eds, for every drive
// alike (a CANopen node, an EtherCAT slave, the drive in this process). And the entries a node's
// object dictionary knows beyond the CiA 402 table, for the page's parameter list: from its
// dictionary or EDS, or for an EtherCAT slave from its CoE SDO information.
#pragma once

#include <vector>

#include "cia402/dictionary/object_dictionary.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/page/parameters.hpp"

namespace cia402::cli {

/// DCF files (CiA 306 §4.6.4): each entry with its present value as ParameterValue; a file read
/// back gives the ParameterValue entries only (a DefaultValue is no configured value).
page::parameter_file_format dcf_parameter_file();

/// The entries of a node's objects (its dictionary, or an EDS) as the page lists them.
std::vector<page::parameter_entry> parameter_entries(const std::vector<dictionary::object_entry>& objects,
                                                     int node_id);
/// The entries an EtherCAT slave's SDO information describes (no defaults or limits: it was asked for
/// none); an entry of a data type the page cannot show as a number or text (REAL32, OCTET_STRING,
/// DOMAIN ...) is left out.
std::vector<page::parameter_entry> parameter_entries(const std::vector<ethercat::ecat_object_description>& objects);

}  // namespace cia402::cli
