// Properties tested like behaviour (STYLE.md, boost-ext/sml): the per-axis state is small and
// trivially copyable, every built-in profile passes check_profile, and check_profile refuses each
// kind of malformed table with a reason and the offending row.
#include <array>
#include <cstring>
#include <set>
#include <string>
#include <type_traits>

#include "test_support.hpp"

namespace cia402 {
namespace {

static_assert(sizeof(axis) <= 16, "an axis must fit in 16 bytes");
static_assert(std::is_trivially_copyable_v<axis>, "an axis is copied and compared as bytes");
static_assert(std::is_trivially_copyable_v<drive_inputs>);
static_assert(std::is_trivially_copyable_v<drive_outputs>);
static_assert(std::is_trivially_copyable_v<transition_row>);
static_assert(std::is_trivially_copyable_v<profile>, "a profile is a view: copying it is cheap");
static_assert(sizeof(stored_row) == 9 && alignof(stored_row) == 1,
              "a stored row is 9 bytes with no padding: rows are most of a profile's flash");

TEST(footprint, axis_fits_in_sixteen_bytes_and_is_trivially_copyable) {
  EXPECT_LE(sizeof(axis), 16u);
  EXPECT_TRUE(std::is_trivially_copyable_v<axis>);
  EXPECT_TRUE(std::is_standard_layout_v<axis>);
}

TEST(footprint, axis_copy_is_an_independent_axis) {
  const profile& p = standard_profile();
  axis a = make_axis(p);
  drive_inputs in;
  step(p, a, in);
  axis copy;
  std::memcpy(&copy, &a, sizeof(axis));
  in.control_word = 0x06;
  step(p, a, in);
  step(p, a, in);
  EXPECT_EQ(a.current, state::ready_to_switch_on);
  EXPECT_EQ(copy.current, state::not_ready_to_switch_on) << "the copy did not move";
  step(p, copy, in);
  step(p, copy, in);
  EXPECT_TRUE(test::same_bytes(a, copy)) << "the copy behaves like the original";
}

TEST(footprint, every_builtin_profile_passes_check_profile) {
  ASSERT_EQ(builtin_profile_count(), 5u);
  for (const profile* p : test::all_builtins()) {
    int row = 99;
    const char* reason = check_profile(*p, row);
    EXPECT_EQ(reason, nullptr) << p->name << ": " << reason << " (row " << row << ")";
    EXPECT_EQ(row, -1) << p->name;
    EXPECT_NE(std::string(p->seed), "") << p->name << " cites its seed";
    EXPECT_EQ(find_builtin_profile(p->name), p);
  }
  EXPECT_EQ(&standard_profile(), find_builtin_profile("cia402"));
  EXPECT_EQ(find_builtin_profile("no-such-profile"), nullptr);
}

TEST(footprint, custom_profile_copied_from_a_builtin_passes_and_behaves_the_same) {
  custom_profile c(standard_profile());
  int row = 0;
  EXPECT_EQ(check_profile(c, row), nullptr);
  const profile& p = c;
  axis a = make_axis(p), b = make_axis(standard_profile());
  drive_inputs in;
  for (std::uint16_t cw : {0x00, 0x00, 0x06, 0x0F, 0x0F, 0x02, 0x02, 0x00}) {
    in.control_word = cw;
    EXPECT_TRUE(test::same_outputs(step(p, a, in), step(standard_profile(), b, in)));
  }
}

// Each malformed table is refused with a reason naming the problem and the row it is in.
struct malformation {
  const char* name;
  const char* reason_mentions;
  int row;  ///< the row expected in `row`, or -1
  void (*spoil)(custom_profile&);
  /// Or, where `spoil` is null, the change made to that row alone.
  void (*spoil_row)(transition_row&) = nullptr;
};

transition_row rows_of(const custom_profile& c, int i) { return c.get().row(static_cast<std::size_t>(i)); }

void replace_row(custom_profile& c, int i, transition_row r) {
  transition_row rows[max_rows];
  const profile& v = c.get();
  for (int k = 0; k < v.row_count; ++k) rows[k] = v.row(static_cast<std::size_t>(k));
  rows[i] = r;
  ASSERT_TRUE(c.set_rows(rows, v.row_count));
  c.finalize();
}

// Sets option `o` to `supported` and `default_value` (both unchecked) and finalizes.
template <option o, std::uint16_t supported, std::int8_t default_value>
void set_option(custom_profile& c) {
  c.settings().options[static_cast<int>(o)] = {supported, default_value};
  c.finalize();
}

void replace_decoder_rule(custom_profile& c, int i, decoder_rule d) {
  decoder_rule rules[max_decoder_rules];
  const profile& v = c.get();
  for (int k = 0; k < v.decoder_size; ++k) rules[k] = v.decoder[k];
  rules[i] = d;
  ASSERT_TRUE(c.set_decoder(rules, v.decoder_size));
  c.finalize();
}

const malformation malformations[] = {
    {"transition number 18", "0..17", 3, nullptr, [](transition_row& r) { r.number = 18; }},
    {"row from no state", "no state", 4, nullptr, [](transition_row& r) { r.from = 0; }},
    {"row from a state beyond FAULT", "unknown state", 2, nullptr,
     [](transition_row& r) { r.from = static_cast<std::uint16_t>(r.from | (1u << 12)); }},
    {"row to START", "unknown state", 5, nullptr, [](transition_row& r) { r.to = state::start; }},
    {"row to a state number out of range", "unknown state", 5, nullptr,
     [](transition_row& r) { r.to = static_cast<state>(9); }},
    {"row without a trigger", "no trigger", 6, nullptr,
     [](transition_row& r) { r.any = fact_set(); }},
    {"row with an unknown fact", "unknown fact", 7, nullptr,
     [](transition_row& r) { r.all = fact_set(1u << 30); }},
    {"row that requires and forbids dc_link", "requires and forbids", 3, nullptr,
     [](transition_row& r) {
       r.all = fact_set(fact::dc_link);
       r.none = fact_set(fact::dc_link);
     }},
    {"row with an unknown stop", "stop", 8, nullptr,
     [](transition_row& r) { r.stop = static_cast<row_stop>(9); }},
    {"row with unknown flags", "flags", 9, nullptr, [](transition_row& r) { r.flags = 0x80; }},
    {"decoder rule masking bit 5", "bits other than 0..4", -1,
     [](custom_profile& c) { replace_decoder_rule(c, 0, {0x22, 0x00, command::disable_voltage}); }},
    {"decoder rule value outside its mask", "outside its mask", -1,
     [](custom_profile& c) { replace_decoder_rule(c, 1, {0x04, 0x08, command::quick_stop}); }},
    {"decoder rule yielding an unknown command", "unknown command", -1,
     [](custom_profile& c) {
       replace_decoder_rule(c, 2, {0x01, 0x00, static_cast<command>(6)});
     }},
    {"option default the profile does not support", "default", -1,
     set_option<option::quick_stop, 0x0003, 5>},
    {"fixed option value out of range", "out of range", -1, set_option<option::halt, 0, 40>},
    {"halt code 0, which the standard reserves", "does not define", -1,
     set_option<option::halt, 0x0003, 1>},
    {"quick stop code 9", "does not define", -1, set_option<option::quick_stop, 0x0204, 2>},
    {"fixed fault reaction 7", "out of range", -1, set_option<option::fault_reaction, 0, 7>},
    {"status pattern with bit 4", "status pattern", -1,
     [](custom_profile& c) {
       c.settings().states[static_cast<int>(state::switched_on)].status_pattern = 0x33;
       c.finalize();
     }},
    {"state with an unknown activity", "activity", -1,
     [](custom_profile& c) {
       c.settings().states[static_cast<int>(state::fault)].activity =
           static_cast<state_activity>(7);
       c.finalize();
     }},
};

TEST(footprint, check_profile_refuses_each_malformed_table_with_reason_and_row) {
  for (const malformation& m : malformations) {
    SCOPED_TRACE(m.name);
    custom_profile c(standard_profile());
    if (m.spoil != nullptr) {
      m.spoil(c);
    } else {
      transition_row r = rows_of(c, m.row);
      m.spoil_row(r);
      replace_row(c, m.row, r);
    }
    int row = 99;
    const char* reason = check_profile(c, row);
    ASSERT_NE(reason, nullptr) << "accepted";
    EXPECT_NE(std::string(reason).find(m.reason_mentions), std::string::npos) << reason;
    EXPECT_EQ(row, m.row) << reason;
  }
}

TEST(footprint, custom_profile_refuses_tables_beyond_its_capacity_and_keeps_the_old_ones) {
  custom_profile c(standard_profile());
  const std::uint8_t rows_before = c.get().row_count;
  const std::uint8_t rules_before = c.get().decoder_size;
  transition_row too_many[max_rows + 1] = {};
  decoder_rule too_many_rules[max_decoder_rules + 1] = {};
  EXPECT_FALSE(c.set_rows(too_many, max_rows + 1));
  EXPECT_FALSE(c.set_decoder(too_many_rules, max_decoder_rules + 1));
  EXPECT_FALSE(c.set_rows(nullptr, 3));
  EXPECT_FALSE(c.set_name(std::string(40, 'x')));
  EXPECT_EQ(c.get().row_count, rows_before);
  EXPECT_EQ(c.get().decoder_size, rules_before);
  EXPECT_STREQ(c.get().name, "cia402");
  int row = 0;
  EXPECT_EQ(check_profile(c, row), nullptr);
}

// A profile written in code stores its rows at compile time: two rows, three sets, two distinct.
constexpr transition_row user_rows[] = {
    {0, state::not_ready_to_switch_on, state_bit(state::start), fact_set(fact::automatic), {}, {},
     row_stop::immediate, 0},
    {1, state::switch_on_disabled, state_bit(state::not_ready_to_switch_on),
     fact_set(fact::automatic), {}, {}, row_stop::immediate, 0},
};
static_assert(stored_rows<user_rows>.sets.size() == 2, "automatic, and the empty set");
static_assert(stored_rows<user_rows>.rows[0].any == stored_rows<user_rows>.rows[1].any);
static_assert(stored_rows<user_rows>.sets[stored_rows<user_rows>.rows[1].any] ==
              static_cast<std::uint32_t>(fact::automatic));
static_assert(stored_rows<user_rows>.rows[1].from() == state_bit(state::not_ready_to_switch_on));

// The rows' fact sets are stored once per profile: each distinct set in the pool once, every row's
// indices naming the set it was written with.
TEST(footprint, a_profile_stores_each_distinct_fact_set_once) {
  for (const profile* p : test::all_builtins()) {
    std::set<std::uint32_t> distinct;
    for (std::size_t i = 0; i < p->row_count; ++i) {
      const transition_row r = p->row(i);
      distinct.insert({r.any.bits(), r.all.bits(), r.none.bits()});
    }
    EXPECT_EQ(p->fact_set_count, distinct.size()) << p->name;
    const std::set<std::uint32_t> pool(p->fact_sets, p->fact_sets + p->fact_set_count);
    EXPECT_EQ(pool, distinct) << p->name;
    const custom_profile c(*p);
    EXPECT_EQ(c.get().fact_set_count, p->fact_set_count) << p->name << ", copied";
    for (std::size_t i = 0; i < p->row_count; ++i) {
      const transition_row x = c.get().row(i), y = p->row(i);
      EXPECT_TRUE(x.number == y.number && x.to == y.to && x.from == y.from && x.any == y.any &&
                  x.all == y.all && x.none == y.none && x.stop == y.stop && x.flags == y.flags)
          << p->name << " row " << i;
    }
  }
}

TEST(footprint, check_profile_refuses_a_row_that_names_a_fact_set_the_profile_lacks) {
  const profile& base = standard_profile();
  std::array<stored_row, max_rows> rows{};
  for (std::size_t i = 0; i < base.row_count; ++i) rows[i] = base.rows[i];
  rows[4].none = base.fact_set_count;  // one past the pool
  profile p = base;
  p.rows = rows.data();
  int row = -1;
  const char* reason = check_profile(p, row);
  ASSERT_NE(reason, nullptr);
  EXPECT_STREQ(reason, "row names a fact set the profile does not have");
  EXPECT_EQ(row, 4);
  rows[4].none = base.rows[4].none;
  EXPECT_EQ(check_profile(p, row), nullptr);
}

TEST(footprint, a_copied_custom_profile_points_at_its_own_tables) {
  custom_profile a(standard_profile());
  custom_profile b = a;
  EXPECT_NE(a.get().rows, b.get().rows);
  EXPECT_NE(a.get().fact_sets, b.get().fact_sets);
  EXPECT_NE(a.get().decoder, b.get().decoder);
  EXPECT_NE(static_cast<const void*>(a.get().name), static_cast<const void*>(b.get().name));
  b.set_name("changed");
  b.finalize();
  EXPECT_STREQ(a.get().name, "cia402");
  EXPECT_STREQ(b.get().name, "changed");
}

}  // namespace
}  // namespace cia402
