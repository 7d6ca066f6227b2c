// The CoE slave (ethercat/slave) is generic: any dictionary::device behind it, described by its own
// dictionary; its process data bound on the way to SAFE-OP keep the dictionary's rules; 0x1017 is
// served on EtherCAT too; and our master moves objects longer than a mailbox in segments both ways.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cia402/apps/virtual_drive_slave.hpp"
#include "cia402/dictionary/object_builders.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/ethercat/slave/coe_slave.hpp"
#include "cia402/profile.hpp"

namespace cia402::ethercat {
namespace {

using dictionary::access;
using cia402::data_type;
using dictionary::object_category;
using dictionary::object_code;

// A device of another profile: a set-point register (0x2100) whose double is the actual value
// (0x2101). It takes any value: the limits of 0x2100 (0..1000) are the dictionary's alone.
class register_device final : public dictionary::device {
 public:
  sdo_abort read(std::uint16_t index, std::uint8_t sub, std::int64_t& v) noexcept override {
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    if (index == 0x2100) v = setpoint;
    else if (index == 0x2101) v = 2 * setpoint;
    else return sdo_abort::object_does_not_exist;
    return sdo_abort::none;
  }
  sdo_abort write(std::uint16_t index, std::uint8_t sub, std::int64_t v) noexcept override {
    if (sub != 0) return sdo_abort::sub_index_does_not_exist;
    if (index != 0x2100) return sdo_abort::read_only_object;
    setpoint = v;
    changed(0x2101, 0);
    return sdo_abort::none;
  }
  std::uint32_t step(std::uint32_t) noexcept override { return 1000; }
  void set_connection_lost(bool lost) noexcept override { connection_lost = lost; }
  void reset() noexcept override { setpoint = 0; }
  std::int64_t setpoint = 0;
  bool connection_lost = false;
};

const std::string long_text(300, 'x');

// With a control and a status word (stored in the dictionary), so our master, which runs CiA 402
// drives, takes it to OP.
coe_slave_config register_config() {
  using dictionary::limited;
  using dictionary::mappable;
  using dictionary::on_device;
  using dictionary::variable;
  coe_slave_config c;
  c.objects = {
      dictionary::single(0x1000, object_category::mandatory,
                      variable(0, "Device type", data_type::unsigned32, access::ro, 0x00000191)),
      dictionary::single(0x1008, object_category::optional,
                      dictionary::text(0, "Manufacturer device name", access::constant, "register box", 0)),
      dictionary::group(0x1018, "Identity object", object_code::record, object_category::mandatory,
                     {variable(0, "Highest sub-index supported", data_type::unsigned8, access::ro, 4),
                      variable(1, "Vendor-ID", data_type::unsigned32, access::ro, 0x00ABCDEF),
                      variable(2, "Product code", data_type::unsigned32, access::ro, 0x401),
                      variable(3, "Revision number", data_type::unsigned32, access::ro, 1),
                      variable(4, "Serial number", data_type::unsigned32, access::ro, 9)}),
      dictionary::single(0x2100, object_category::manufacturer,
                      limited(mappable(on_device(variable(0, "Set-point", data_type::unsigned16, access::rw))), 0, 1000)),
      dictionary::single(0x2101, object_category::manufacturer,
                      mappable(on_device(variable(0, "Actual", data_type::integer32, access::ro)))),
      dictionary::single(0x2200, object_category::manufacturer, dictionary::text(0, "Notes", access::rw, long_text, 300)),
      dictionary::single(0x6040, object_category::mandatory, mappable(variable(0, "Controlword", data_type::unsigned16, access::rw))),
      dictionary::single(0x6041, object_category::mandatory,
                      mappable(variable(0, "Statusword", data_type::unsigned16, access::ro, 0x0250)))};
  c.rx_pdo = detail::make_pdo_map({{0x6040, 0, 16}, {0x2100, 0, 16}}, pdo_maps::on_change);
  c.tx_pdo = detail::make_pdo_map({{0x6041, 0, 16}, {0x2101, 0, 32}}, pdo_maps::on_change);
  c.vendor_name = "a test";
  c.group_name = "Registers";
  return c;
}

// A line on virtual time: frames pass every controller at once; waiting runs every application.
class line final : public master_link {
 public:
  template <typename Slave>
  Slave& add(std::unique_ptr<Slave> s) {
    Slave& ref = *s;
    wire.add(ref.controller());
    steps.push_back([&ref](std::uint32_t us) { ref.step(us); });
    owned.push_back(std::shared_ptr<void>(std::move(s)));
    return ref;
  }
  bool exchange(std::vector<std::uint8_t>& frame) override { return wire.pass(frame) == frame_error::none; }
  std::uint64_t now_us() override { return now; }
  void wait_us(std::uint32_t us) override {
    now += us;
    for (auto& step : steps) step(us);
  }
  chain wire;
  std::vector<std::function<void(std::uint32_t)>> steps;
  std::vector<std::shared_ptr<void>> owned;
  std::uint64_t now = 0;
};

TEST(coe_slave, a_device_of_another_profile_is_described_by_its_own_dictionary) {
  register_device dev;
  coe_slave slave(dev, register_config());
  const slave_description& d = slave.description();
  EXPECT_EQ(d.profile_number, 401) << "0x1000's low word";
  EXPECT_EQ(d.device_name, "register box");
  EXPECT_EQ(d.vendor_id, 0x00ABCDEFu);
  EXPECT_EQ(d.product_code, 0x401u);
  EXPECT_EQ(d.serial, 9u);
  ASSERT_EQ(d.rx_pdos.size(), 1u);
  ASSERT_EQ(d.rx_pdos[0].entries.size(), 2u);
  EXPECT_EQ(d.rx_pdos[0].entries[1].name, "Set-point");
  EXPECT_EQ(d.sync_managers[3].length, 6) << "the status word and the INTEGER32";
  for (std::uint16_t own : {0x1017, 0x1600, 0x1601, 0x1A00, 0x1A01, 0x1C00, 0x1C12, 0x1C13}) {
    EXPECT_NE(slave.dictionary().object(own), nullptr) << std::hex << own;
  }
}

TEST(coe_slave, a_device_table_that_holds_the_slaves_own_objects_is_refused) {
  coe_slave_config c = register_config();
  c.objects.push_back(dictionary::single(0x1C12, object_category::optional,
                                      dictionary::variable(0, "RxPDO assign", data_type::unsigned8, access::rw)));
  register_device dev;
  EXPECT_THROW(coe_slave(dev, c), std::invalid_argument);
}

TEST(coe_slave, objects_longer_than_a_mailbox_travel_in_segments_both_ways) {
  register_device dev;  // outlives the line, whose slave refers to it
  line l;
  l.add(std::make_unique<coe_slave>(dev, register_config()));
  ecat_master m(l, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_pre_operational()) << m.error();
  // 300 bytes: a 128-byte mailbox holds 112 of them, segments of 119 the rest.
  ecat_sdo_result r = m.sdo_read(0, 0x2200, 0);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(std::string(r.data.begin(), r.data.end()), long_text);
  const std::string written(250, 'y');
  r = m.sdo_write_bytes(0, 0x2200, 0, std::vector<std::uint8_t>(written.begin(), written.end()));
  ASSERT_TRUE(r.ok) << r.error;
  r = m.sdo_read(0, 0x2200, 0);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(std::string(r.data.begin(), r.data.end()), written);
  // One byte more than the object holds: the slave's abort, in words, and the old value kept.
  r = m.sdo_write_bytes(0, 0x2200, 0, std::vector<std::uint8_t>(301, 'z'));
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.aborted) << r.error;
  EXPECT_EQ(r.abort, sdo_abort::data_type_length_too_high);
  r = m.sdo_read(0, 0x2200, 0);
  EXPECT_EQ(std::string(r.data.begin(), r.data.end()), written);
  // And the short ones still expedited.
  ASSERT_TRUE(m.sdo_write(0, 0x2100, 0, 21, 2).ok);
  EXPECT_EQ(m.sdo_read(0, 0x2101, 0).value(true), 42);
}

struct drive_line {
  line l;
  std::vector<apps::virtual_drive_slave*> drives;
  ecat_master master{l, standard_profile()};
  explicit drive_line(int n) {
    for (int i = 0; i < n; ++i) {
      drives.push_back(&l.add(std::make_unique<apps::virtual_drive_slave>(standard_profile(), static_cast<std::uint32_t>(i + 1))));
    }
  }
  void run(int cycles) {
    for (int i = 0; i < cycles; ++i) {
      (void)master.cycle();
      l.wait_us(1000);
    }
  }
};

TEST(coe_slave, the_producer_heartbeat_time_is_written_and_read_back_on_ethercat_as_on_can) {
  drive_line d(1);
  ASSERT_TRUE(d.master.scan()) << d.master.error();
  ASSERT_TRUE(d.master.bring_to_pre_operational()) << d.master.error();
  ASSERT_TRUE(d.master.sdo_write(0, 0x1017, 0, 100, 2).ok);
  const ecat_sdo_result r = d.master.sdo_read(0, 0x1017, 0);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.value(false), 100);
  EXPECT_EQ(r.data.size(), 2u) << "UNSIGNED16";
}

TEST(coe_slave, a_value_the_outputs_carry_keeps_the_dictionarys_limits_as_an_sdo_write_does) {
  register_device dev;
  line l;
  l.add(std::make_unique<coe_slave>(dev, register_config()));
  ecat_master m(l, standard_profile());
  ASSERT_TRUE(m.scan()) << m.error();
  ASSERT_TRUE(m.bring_to_operational()) << m.error();
  const auto run = [&] {
    for (int i = 0; i < 5; ++i) {
      (void)m.cycle();
      l.wait_us(1000);
    }
  };
  ASSERT_TRUE(m.set_output(0, 0x2100, 500));
  run();
  EXPECT_EQ(dev.setpoint, 500);
  EXPECT_EQ(m.input(0, 0x2101), 1000) << "the inputs bound to the device's actual value";
  ASSERT_TRUE(m.set_output(0, 0x2100, 1001));
  run();
  EXPECT_EQ(dev.setpoint, 500) << "above the entry's limit: refused, as over SDO (0x06090031)";
  const ecat_sdo_result sdo = m.sdo_write(0, 0x2100, 0, 1001, 2);
  EXPECT_EQ(sdo.abort, sdo_abort::value_too_high);
}

TEST(coe_slave, an_entry_cleared_after_its_count_stops_safe_op_with_invalid_output_mapping) {
  drive_line d(1);
  ASSERT_TRUE(d.master.scan()) << d.master.error();
  ASSERT_TRUE(d.master.bring_to_pre_operational()) << d.master.error();
  const auto count = static_cast<std::uint8_t>(d.master.sdo_read(0, 0x1600, 0).value(false));
  ASSERT_GT(count, 1);
  ASSERT_TRUE(d.master.sdo_write(0, 0x1600, count, 0, 4).ok) << "an entry may be written 0 at any time";
  EXPECT_FALSE(d.master.bring_to_operational());
  EXPECT_NE(d.master.error().find("0x0025"), std::string::npos) << d.master.error();
  EXPECT_EQ(d.drives[0]->state(), al_state::pre_operational);
}

}  // namespace
}  // namespace cia402::ethercat
