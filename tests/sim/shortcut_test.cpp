// step_axis() takes two shortcuts: it skips the core when the axis is settled (its core and every
// source of the core's inputs as a cycle whose step changed nothing left them), and it runs a
// settled csp axis's cycle without a call. Both must change nothing: here every axis runs beside a
// twin whose settled state is cleared before each cycle, so the twin always takes the full cycle,
// and the two must agree on everything after every cycle, under random commands, set-points,
// modes, option codes, faults, STO, DC link and link loss, in every built-in profile.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <sstream>
#include <string>

#include "cia402/master.hpp"
#include "cia402/objects.hpp"
#include "cia402/sim/virtual_drive.hpp"
#include "cia402/words.hpp"

namespace {

using namespace cia402;
using namespace cia402::sim;

// Everything an axis shows or keeps, apart from the shortcut's own memory, as text: a difference
// names itself in the failure. With `objects`, every object of the table as read_object() gives it.
std::string observe(const profile& p, const plant_constants& k, const axis_state& a, bool objects) {
  std::ostringstream s;
  for (std::size_t i = 0; objects && i < drive_object_count(); ++i) {
    const object_description& o = drive_object(i);
    std::int64_t v = 0;
    const sdo_abort r = read_object(p, k, a, o.index, o.sub, v);
    s << std::hex << o.index << '.' << int{o.sub} << '=' << std::dec << v << '/'
      << static_cast<std::uint32_t>(r) << ' ';
  }
  const drive_inputs in = plant_inputs(k, a);
  s << "\ninputs " << in.fault_code << ' ' << in.dc_link << in.sto << in.remote << in.connection_lost
    << ' ' << in.control_word << ' ' << in.status_bits << ' ' << int{in.fault_class} << ' '
    << in.standstill << in.brake_engaged << ' ' << in.actual_speed_rpm;
  const axis& c = a.core;
  s << "\ncore " << int(c.current) << ' ' << int{c.flags} << ' ' << int{c.pending_row} << ' '
    << int{c.last_transition} << ' ' << c.error_code << ' ' << int{c.stop_code};
  for (const std::int8_t o : c.options) s << ' ' << int{o};
  const drive_outputs& out = a.last;
  s << "\nlast " << int(out.current) << ' ' << out.status_word << ' ' << int{out.transition} << ' '
    << int(out.ramp) << ' ' << out.torque << out.brake_released << out.clear_setpoints << ' '
    << out.error_code << ' ' << int{out.error_register};
  s << "\nshaft " << a.home_shift << ' ' << a.previous_position << ' ' << a.in_velocity_window_us << ' '
    << a.above_velocity_threshold_us << ' ' << a.interpolation_from << ' ' << a.interpolation_to << ' '
    << a.interpolation_elapsed_us << ' ' << int(a.homing.phase()) << ' ' << digital_inputs(k, a) << ' '
    << a.pv_set_point << a.pv_set_point_cut << ' ' << a.limit_braking_reach;
  s << "\nplant " << a.velocity << ' ' << a.position << ' ' << a.position_fraction << ' ' << a.demand
    << ' ' << a.torque << ' ' << a.torque_demand << ' ' << a.following_error_us << ' '
    << a.mode_status << ' ' << int{a.flags} << ' ' << a.brake_timer << ' ' << int{a.operation_mode};
  for (int i = 0; i < max_fault_causes; ++i) s << ' ' << a.fault_codes[i] << ':' << int{a.fault_classes[i]};
  const motion::shaft pp = a.pp.state();
  s << "\npp " << pp.position << ' ' << pp.fraction << ' ' << pp.velocity;
  return s.str();
}

constexpr std::uint16_t words[] = {0x0000, 0x0006, 0x0007, 0x000F, 0x000B, 0x0080, 0x0086,
                                   0x008F, 0x010F, 0x001F, 0x003F, 0x005F, 0x021F, 0x0002};
constexpr std::int64_t modes[] = {1, 3, 4, 6, 8, 8, 8, 9, 10};

// A csp master's stream: the next set-point `per_cycle` increments on from the shaft, a constant
// velocity most of the time (the cycle the shortcut is for), changed now and then.
struct stream {
  std::int64_t per_cycle = 20;
  std::uint16_t shutdown = 0x0006;  // the profile's own words (encode_command)
  std::uint16_t enable = 0x000F;
  int recovering = -1;  // cycles into a recovery to a running csp axis, -1 when none runs
};

// One cycle's disturbance of an axis, the same for both twins: the csp master's next set-point,
// and now and then anything else a master or the plant can do.
void disturb(drive_view d, std::mt19937& rng, stream& st) {
  const auto pick = [&rng](std::uint32_t n) { return static_cast<std::uint32_t>(rng() % n); };
  const std::int64_t here = d.position();
  d.write(0x607A, 0, here + st.per_cycle);
  // A recovery, as a master does it: causes gone, fault reset edge, shut down, enable.
  if (st.recovering >= 0) {
    switch (st.recovering++) {
      case 0:
        d.clear_faults();
        d.set_sto(false);
        d.set_dc_link(true);
        d.set_connection_lost(false);
        d.write(0x6060, 0, 8);
        d.write(0x6040, 0, 0x0000);
        break;
      case 1: d.write(0x6040, 0, 0x0080); break;
      case 2: d.write(0x6040, 0, st.shutdown); break;
      case 5: d.write(0x6040, 0, st.enable); break;
      case 8: st.recovering = -1; break;
      default: break;
    }
    return;
  }
  if (pick(1000) >= 8) return;
  switch (pick(33)) {
    case 0: case 1: case 2:
      d.write(0x6040, 0, words[pick(sizeof words / sizeof words[0])]);
      break;
    case 3: case 4: case 5: st.recovering = 0; break;
    case 6: d.write(0x6060, 0, modes[pick(sizeof modes / sizeof modes[0])]); break;
    case 7: d.write(0x607A, 0, here + static_cast<std::int64_t>(pick(20001)) - 10000); break;  // a jump
    case 8: st.per_cycle = static_cast<std::int64_t>(pick(201)) - 100; break;
    case 9: d.write(0x60FF, 0, static_cast<std::int64_t>(pick(4001)) - 2000); break;
    case 10: d.write(0x6071, 0, static_cast<std::int64_t>(pick(1201)) - 600); break;
    case 11: d.write(0x6065, 0, pick(2) ? 0xFFFFFFFFu : pick(3000)); break;
    case 12: d.write(0x6066, 0, pick(20)); break;
    case 13:
      d.write(0x607D, 1, static_cast<std::int64_t>(pick(40001)) - 30000);
      d.write(0x607D, 2, static_cast<std::int64_t>(pick(40001)) - 10000);
      break;
    case 14: d.write(static_cast<std::uint16_t>(0x605A + pick(5)), 0, static_cast<std::int64_t>(pick(10)) - 1); break;
    case 15: d.inject_fault(pick(2) ? 0x2310 : 0x7500, static_cast<std::uint8_t>(pick(5))); break;
    case 16: d.clear_faults(); break;
    case 17: d.set_sto(pick(3) == 0); break;
    case 18: d.set_dc_link(pick(4) != 0); break;
    case 19: d.set_connection_lost(pick(4) == 0); break;
    case 20: d.write(0x608F, 1, pick(2) ? 10000 : 4096 + pick(3)); break;  // off the usual resolution
    case 21: d.write(0x6007, 0, pick(4)); break;
    case 22: d.write(0x60B0, 0, static_cast<std::int64_t>(pick(201)) - 100); break;
    case 23: d.write(0x6098, 0, pick(2) ? 35 : (pick(2) ? 3 : 34)); break;
    case 24:  // a halt on the current or voltage limit ramp (status bit 11 while it brakes)
      d.write(0x605D, 0, 3 + pick(2));
      d.write(0x6040, 0, st.enable | 0x0100);
      break;
    case 25: d.write(0x6040, 0, st.enable); break;  // the halt ends
    case 26:  // a set-point period of 1..4 cycles: interpolation, off the path with no call
      d.write(0x60C2, 1, 1 + pick(4));
      break;
    case 27: d.write(pick(2) ? 0x607F : 0x6080, 0, pick(2) ? 6000 : 300 + pick(5000)); break;  // a speed limit
    case 28: d.write(0x6040, 0, st.enable | 0x0010); break;  // bit 4: a homing start, a pp set-point
    default:  // profile velocity, its target written while the brake may still hold the shaft
      d.write(0x6060, 0, 3);
      d.write(0x60FF, 0, pick(3) == 0 ? 0 : static_cast<std::int64_t>(pick(3001)) - 1500);
      break;
  }
}

TEST(step_axis_shortcuts, every_cycle_equals_the_full_cycle_in_every_profile) {
  const plant_constants k = plant_constants::from({});
  for (std::size_t pi = 0; pi < builtin_profile_count(); ++pi) {
    const profile& p = builtin_profile(pi);
    std::size_t settled_csp_cycles = 0;
    std::size_t skipped = 0;
    for (std::uint32_t seed = 1; seed <= 12; ++seed) {
      axis_state fast = make_axis_state(p);
      axis_state full = make_axis_state(p);
      std::mt19937 rng_fast(seed);
      std::mt19937 rng_full(seed);
      stream stream_fast;
      ASSERT_TRUE(encode_command(p, command::shutdown, 0, stream_fast.shutdown));
      ASSERT_TRUE(encode_command(p, command::enable_operation, 0, stream_fast.enable));
      stream stream_full = stream_fast;
      // Enabled in csp first, so most of the run is the streaming the shortcut is for.
      for (axis_state* a : {&fast, &full}) {
        drive_view d(p, k, *a);
        d.write(0x6060, 0, 8);
        d.write(0x6040, 0, stream_fast.shutdown);
      }
      for (std::uint64_t c = 0; c < 6000; ++c) {
        if (c == 3) {
          drive_view(p, k, fast).write(0x6040, 0, stream_fast.enable);
          drive_view(p, k, full).write(0x6040, 0, stream_fast.enable);
        }
        if (c > 200) {
          disturb(drive_view(p, k, fast), rng_fast, stream_fast);
          disturb(drive_view(p, k, full), rng_full, stream_full);
        }
        const bool was_settled = fast.settled_valid;
        skipped += was_settled && std::memcmp(fast.settled, &fast, core_source_bytes) == 0;
        settled_csp_cycles += was_settled && fast.operation_mode == 8 &&
                              fast.last.current == state::operation_enabled;
        full.settled_valid = false;  // the twin's core decides every cycle
        step_axis(p, k, fast);
        step_axis(p, k, full);
        const bool objects = c % 64 == 0;
        const std::string a = observe(p, k, fast, objects);
        const std::string b = observe(p, k, full, objects);
        ASSERT_EQ(a, b) << p.name << ", seed " << seed << ", cycle " << c;
      }
    }
    // The run exercised what it checks.
    std::printf("%s: core skipped in %zu cycles, %zu of them a running csp axis's, of %d\n", p.name,
                skipped, settled_csp_cycles, 12 * 6000);
    EXPECT_GT(skipped, 40000u) << p.name;
    EXPECT_GT(settled_csp_cycles, 15000u) << p.name;
  }
}

// Two axes of one profile, one stepped with the shortcuts and one always in full.
struct twins {
  const profile& p = standard_profile();
  const plant_constants k = plant_constants::from({});
  axis_state fast = make_axis_state(p);
  axis_state full = make_axis_state(p);

  template <typename F>
  void each(F f) {
    f(drive_view(p, k, fast));
    f(drive_view(p, k, full));
  }
  // Steps both `cycles` times, the same after every one; false (with a failure) if not.
  bool step(int cycles = 1) {
    for (int i = 0; i < cycles; ++i) {
      full.settled_valid = false;
      step_axis(p, k, fast);
      step_axis(p, k, full);
      const std::string a = observe(p, k, fast, true);
      const std::string b = observe(p, k, full, true);
      EXPECT_EQ(a, b);
      if (a != b) return false;
    }
    return true;
  }
  // Enabled in csp, streaming `per_cycle` increments a cycle, for `cycles` cycles.
  bool stream(std::int64_t per_cycle, int cycles) {
    for (int i = 0; i < cycles; ++i) {
      each([&](drive_view d) { d.write(0x607A, 0, d.position() + per_cycle); });
      if (!step()) return false;
    }
    return true;
  }
  bool enable_in_csp() {
    each([](drive_view d) {
      d.write(0x6060, 0, 8);
      d.write(0x6040, 0, 0x0006);
    });
    if (!step(3)) return false;
    each([](drive_view d) { d.write(0x6040, 0, 0x000F); });
    return step(60);  // past the brake release
  }
};

// The window 0x6065 is no source of the core's inputs: a settled axis whose error was beyond the
// old window finds itself within a wider one, and the time spent beyond it must start again.
TEST(step_axis_shortcuts, a_wider_following_error_window_restarts_the_time_beyond_it) {
  twins t;
  t.each([](drive_view d) {
    d.write(0x6065, 0, 10);     // each cycle's 20 increments are beyond it
    d.write(0x6066, 0, 1000);   // for a second before the fault
  });
  ASSERT_TRUE(t.enable_in_csp());
  ASSERT_TRUE(t.stream(20, 100));
  EXPECT_GT(t.fast.following_error_us, 0u);
  t.each([](drive_view d) { d.write(0x6065, 0, 100); });
  ASSERT_TRUE(t.stream(20, 10));
  EXPECT_EQ(t.fast.following_error_us, 0u);
  t.each([](drive_view d) { d.write(0x6065, 0, 10); });
  ASSERT_TRUE(t.stream(20, 20));
}

// The software limits are no source of the core's inputs either: written while a csp axis stands
// at its set-point, they cut the demand, and status bit 11 must follow at once.
TEST(step_axis_shortcuts, software_limits_written_under_a_standing_csp_axis_set_bit_11) {
  twins t;
  ASSERT_TRUE(t.enable_in_csp());
  ASSERT_TRUE(t.stream(0, 20));
  const std::int64_t here = t.fast.position;
  t.each([&](drive_view d) {
    d.write(0x607A, 0, here + 5);
    d.write(0x607D, 1, here - 1000);
    d.write(0x607D, 2, here);
  });
  ASSERT_TRUE(t.step(5));
  EXPECT_NE(t.fast.mode_status & status_bit::internal_limit_active, 0u);
}

// A halt (bit 8) stops csp on the 0x605D ramp and holds the axis while the master streams on; a
// quick stop that stays in QUICK STOP ACTIVE (0x605A = 6) holds it too. Neither runs the csp path.
TEST(step_axis_shortcuts, a_halted_or_quick_stopped_csp_axis_stays_where_it_stopped) {
  for (const std::uint16_t stop : {std::uint16_t{0x010F}, std::uint16_t{0x000B}}) {
    twins t;
    t.each([](drive_view d) { d.write(0x605A, 0, 6); });
    ASSERT_TRUE(t.enable_in_csp());
    ASSERT_TRUE(t.stream(20, 50));
    t.each([&](drive_view d) { d.write(0x6040, 0, stop); });
    ASSERT_TRUE(t.stream(20, 400));
    const std::int64_t stopped_at = t.fast.position;
    ASSERT_TRUE(t.stream(20, 100));
    EXPECT_EQ(t.fast.position, stopped_at) << "control word " << stop;
  }
}

}  // namespace
