// Our master's process data: the mapping each slave declares (its PDO assignment and mapping,
// read by SDO, every count and length checked before use) learnt into the process image, and the
// sync managers and FMMUs that put the slave's process RAM at its place in the logical image.
#include <string>
#include <vector>

#include "cia402/ethercat/master/ecat_master.hpp"
#include "master_text.hpp"

namespace cia402::ethercat {

using detail::max_mapped_entries;
using detail::put_le;
using detail::reg_fmmu0;
using detail::reg_sm0;
using detail::slave_text;

bool ecat_master::learn_mapping(ecat_slave& s) {
  struct entry {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t bits;
  };
  std::vector<entry> outputs, inputs;
  const std::size_t i = static_cast<std::size_t>(&s - slaves_.data());
  bool from_coe = s.mailbox;
  bool too_many = false;
  const auto read_assigned = [&](std::uint16_t assign, std::vector<entry>& out) {
    const ecat_sdo_result count = sdo_read(i, assign, 0);
    if (!count.ok || count.value(false) > 254) return false;  // sub-indices 1..254 at most
    for (std::int64_t k = 1; k <= count.value(false); ++k) {
      const ecat_sdo_result pdo = sdo_read(i, assign, static_cast<std::uint8_t>(k));
      if (!pdo.ok) return false;
      const auto pdo_index = static_cast<std::uint16_t>(pdo.value(false));
      const ecat_sdo_result n = sdo_read(i, pdo_index, 0);
      if (!n.ok || n.value(false) > 254) return false;
      for (std::int64_t e = 1; e <= n.value(false); ++e) {
        // 254 PDOs of 254 entries are 64,516 SDOs: a mapping longer than any frame ends here.
        if (out.size() >= max_mapped_entries) {
          too_many = true;
          return false;
        }
        const ecat_sdo_result m = sdo_read(i, pdo_index, static_cast<std::uint8_t>(e));
        if (!m.ok) return false;
        const auto v = static_cast<std::uint32_t>(m.value(false));
        out.push_back({static_cast<std::uint16_t>(v >> 16), static_cast<std::uint8_t>(v >> 8),
                       static_cast<std::uint8_t>(v)});
      }
    }
    return true;
  };
  if (from_coe && (!read_assigned(0x1C12, outputs) || !read_assigned(0x1C13, inputs))) {
    if (too_many) {
      return fail(slave_text(s) + ": its PDO assignment maps more than " + std::to_string(max_mapped_entries) +
                  " entries in one direction");
    }
    // A slave without SDO access to its assignment: the SII's default PDOs are what it runs.
    outputs.clear();
    inputs.clear();
    from_coe = false;
  }
  if (!from_coe) {
    for (const pdo_description& p : s.sii.rx_pdos) {
      if (!p.mandatory) continue;
      for (const pdo_entry& e : p.entries) outputs.push_back({e.index, e.sub, e.bits});
    }
    for (const pdo_description& p : s.sii.tx_pdos) {
      if (!p.mandatory) continue;
      for (const pdo_entry& e : p.entries) inputs.push_back({e.index, e.sub, e.bits});
    }
  }
  s.mapping_source = from_coe ? "CoE 0x1C12/0x1C13" : "SII default PDOs";
  const auto keep = [](const std::vector<entry>& list, std::vector<ecat_slave::mapped_object>& out) {
    out.clear();
    unsigned at = 0;
    for (const entry& e : list) {
      out.push_back({e.index, e.sub, e.bits, static_cast<std::uint16_t>(at)});
      at += e.bits;
    }
  };
  keep(outputs, s.outputs);
  keep(inputs, s.inputs);
  const auto place = [](const std::vector<entry>& list, std::uint16_t index, std::uint8_t bits,
                        unsigned& total) -> std::optional<pdo_place> {
    std::optional<pdo_place> found;
    unsigned at = 0;
    for (const entry& e : list) {
      if (e.index == index && e.sub == 0 && e.bits == bits && !found) {
        found = pdo_place{static_cast<std::uint16_t>(at), e.bits};
      }
      at += e.bits;
    }
    total = at;
    return found;
  };
  unsigned out_bits = 0, in_bits = 0;
  for (const entry& e : outputs) out_bits += e.bits;
  for (const entry& e : inputs) in_bits += e.bits;
  if (out_bits + in_bits > 8u * (maximum_frame_size - 100)) {
    return fail(slave_text(s) + ": its process data (" + std::to_string((out_bits + in_bits + 7) / 8) +
                " bytes) does not fit one frame");
  }
  s.control_word = place(outputs, 0x6040, 16, out_bits);
  s.status_word = place(inputs, 0x6041, 16, in_bits);
  s.error_code = place(inputs, 0x603F, 16, in_bits);
  s.position_actual = place(inputs, 0x6064, 32, in_bits);
  s.velocity_actual = place(inputs, 0x606C, 32, in_bits);
  s.mode_display = place(inputs, 0x6061, 8, in_bits);
  if (!s.control_word || !s.status_word) {
    return fail(slave_text(s) + ": its process data (" + s.mapping_source + ") carries no " +
                (s.control_word ? "0x6041 statusword" : "0x6040 controlword") +
                ": not a CiA 402 drive as mapped");
  }
  s.output_bytes = static_cast<std::uint16_t>((out_bits + 7) / 8);
  s.input_bytes = static_cast<std::uint16_t>((in_bits + 7) / 8);
  return true;
}

bool ecat_master::configure_process_data(ecat_slave& s, std::uint32_t& logical) {
  const slave_description& d = s.sii;
  const auto sm_of = [&](sm_type t, int fallback_index, std::uint16_t fallback_start, std::uint8_t fallback_control) {
    for (std::size_t n = 0; n < d.sync_managers.size(); ++n) {
      if (d.sync_managers[n].type == t) {
        return std::tuple{static_cast<int>(n), d.sync_managers[n].start, d.sync_managers[n].control};
      }
    }
    return std::tuple{fallback_index, fallback_start, fallback_control};
  };
  const auto [out_sm, out_start, out_control] = sm_of(sm_type::outputs, 2, 0x1100, 0x64);
  const auto [in_sm, in_start, in_control] = sm_of(sm_type::inputs, 3, 0x1180, 0x20);
  const auto sm_bytes = [](std::uint16_t start, std::uint16_t length, std::uint8_t control) {
    std::vector<std::uint8_t> v;
    put_le(v, start, 2);
    put_le(v, length, 2);
    v.insert(v.end(), {control, 0x00, static_cast<std::uint8_t>(length > 0 ? 1 : 0), 0x00});
    return v;
  };
  if (!write_register(s, static_cast<std::uint16_t>(reg_sm0 + 8 * out_sm), sm_bytes(out_start, s.output_bytes, out_control)) ||
      !write_register(s, static_cast<std::uint16_t>(reg_sm0 + 8 * in_sm), sm_bytes(in_start, s.input_bytes, in_control))) {
    return fail(slave_text(s) + " did not take its process data sync managers");
  }
  const auto fmmu_bytes = [](std::uint32_t log, std::uint16_t length, std::uint16_t physical, std::uint8_t type) {
    std::vector<std::uint8_t> v;
    put_le(v, log, 4);
    put_le(v, length, 2);
    v.insert(v.end(), {0x00, 0x07});  // logical start bit 0, end bit 7: whole bytes
    put_le(v, physical, 2);
    v.insert(v.end(), {0x00, type, static_cast<std::uint8_t>(length > 0 ? 1 : 0), 0, 0, 0});
    return v;
  };
  // The FMMUs the SII names for outputs and inputs, else 0 and 1.
  int out_fmmu = 0, in_fmmu = 1;
  for (std::size_t n = 0; n < d.fmmus.size(); ++n) {
    if (d.fmmus[n] == fmmu_use::outputs) out_fmmu = static_cast<int>(n);
    if (d.fmmus[n] == fmmu_use::inputs) in_fmmu = static_cast<int>(n);
  }
  s.logical_outputs = logical;
  s.logical_inputs = logical + s.output_bytes;
  if (!write_register(s, static_cast<std::uint16_t>(reg_fmmu0 + 16 * out_fmmu),
                      fmmu_bytes(s.logical_outputs, s.output_bytes, out_start, 0x02)) ||
      !write_register(s, static_cast<std::uint16_t>(reg_fmmu0 + 16 * in_fmmu),
                      fmmu_bytes(s.logical_inputs, s.input_bytes, in_start, 0x01))) {
    return fail(slave_text(s) + " did not take its FMMUs");
  }
  logical += s.output_bytes + s.input_bytes;
  return true;
}

}  // namespace cia402::ethercat
