// `cia402 master --ecat IF`: our EtherCAT master on a network interface. Scans the line, prints
// what each slave's SII says, brings the line to OP and then runs the steps asked for, in order, on
// one drive (--position) or all: state, enable, disable, quick-stop, reset, watch, wait MS (keep
// cycling), sdo read|write.
#include <CLI/CLI.hpp>
#include <csignal>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>

#include "cia402/apps/ethercat_link.hpp"
#include "cia402/ethercat/master/ecat_master.hpp"
#include "cia402/state.hpp"
#include "cia402/objects.hpp"
#include "cli/common.hpp"
#include "cli/master.hpp"

namespace cia402::cli {
namespace {

constexpr int usage_error = 2;
constexpr int failed = 1;
volatile std::sig_atomic_t ecat_stop = 0;
extern "C" void request_ecat_master_stop(int) { ecat_stop = 1; }

std::string word(std::uint16_t w) { return hex(w, 4); }

struct step {
  std::string what;  // state, enable, disable, quick-stop, reset, watch, sdo-read, sdo-write
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::int64_t value = 0;
};

// COMMAND OPERANDS... as steps: sdo takes read INDEX[:SUB] or write INDEX[:SUB] VALUE.
std::optional<std::vector<step>> parse_steps(const master_args& a, std::ostream& err) {
  std::vector<std::string> tokens{a.command};
  tokens.insert(tokens.end(), a.operands.begin(), a.operands.end());
  std::vector<step> steps;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& t = tokens[i];
    if (t == "state" || t == "enable" || t == "disable" || t == "quick-stop" || t == "reset" || t == "watch") {
      steps.push_back({t});
      continue;
    }
    if (t == "wait") {
      const auto ms = i + 1 < tokens.size() ? parse_number(tokens[i + 1]) : std::nullopt;
      if (!ms || *ms < 0 || *ms > 3600000) {
        err << "cia402 master --ecat: wait MS: the milliseconds to keep cycling (0..3600000)\n";
        return std::nullopt;
      }
      steps.push_back({"wait", 0, 0, *ms});
      ++i;
      continue;
    }
    if (t != "sdo") {
      err << "cia402 master --ecat: '" << t
          << "' is not a step (state, enable, disable, quick-stop, reset, watch, wait MS, sdo read|write)\n";
      return std::nullopt;
    }
    const bool writing = i + 1 < tokens.size() && tokens[i + 1] == "write";
    const bool reading = i + 1 < tokens.size() && tokens[i + 1] == "read";
    const std::size_t need = writing ? 3 : 2;  // the words after "sdo"
    if ((!writing && !reading) || i + need >= tokens.size()) {
      err << "cia402 master --ecat: sdo read INDEX[:SUB] | sdo write INDEX[:SUB] VALUE\n";
      return std::nullopt;
    }
    const std::string& where = tokens[i + 2];
    const auto colon = where.find(':');
    const auto index = parse_number(where.substr(0, colon));
    const auto sub = colon == std::string::npos ? std::optional<std::int64_t>(0) : parse_number(where.substr(colon + 1));
    if (!index || *index < 0 || *index > 0xFFFF || !sub || *sub < 0 || *sub > 0xFF) {
      err << "cia402 master --ecat: '" << where << "' is not INDEX[:SUB] (e.g. 0x6060 or 0x1018:1)\n";
      return std::nullopt;
    }
    step s{writing ? "sdo-write" : "sdo-read", static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub)};
    if (writing) {
      const auto v = parse_number(tokens[i + 3]);
      if (!v) {
        err << "cia402 master --ecat: '" << tokens[i + 3] << "' is not a number (decimal or 0x hex)\n";
        return std::nullopt;
      }
      s.value = *v;
    }
    steps.push_back(s);
    i += need;
  }
  return steps;
}

}  // namespace

int run_ecat_master(const master_args& a, std::ostream& out, std::ostream& err) {
  profile_choice choice;
  if (!choice.resolve(a.profile, a.profile_file, err)) return usage_error;
  const profile& p = choice.get();
  const auto steps = parse_steps(a, err);
  if (!steps) return usage_error;

  apps::ethercat_link link;
  if (const std::error_code ec = link.open(a.ecat)) {
    err << "cia402 master: cannot open " << a.ecat << ": " << ec.message()
        << (ec.value() == EPERM ? " (a raw socket needs root or CAP_NET_RAW)" : "") << "\n";
    return failed;
  }
  ethercat::ecat_master m(link, p, a.sync_us);
  const auto line = [&](nlohmann::ordered_json j, const std::string& text) {
    if (a.json) {
      out << j.dump() << "\n";
    } else {
      out << text << "\n";
    }
    out.flush();
  };
  if (!m.scan()) {
    err << "cia402 master: " << a.ecat << ": " << m.error() << "\n";
    return failed;
  }
  auto& slaves = m.slaves();
  if (a.position && *a.position >= static_cast<int>(slaves.size())) {
    err << "cia402 master: --position " << *a.position << ": the line has " << slaves.size() << " slave(s)\n";
    return failed;
  }
  line({{"event", "scan"}, {"slaves", slaves.size()}}, "found " + std::to_string(slaves.size()) + " slave(s) on " + a.ecat);
  for (const auto& s : slaves) {
    line({{"event", "slave"}, {"position", s.position}, {"station", hex(s.station, 4)},
          {"vendor_id", hex(s.sii.vendor_id, 8)}, {"product_code", hex(s.sii.product_code, 8)},
          {"revision", hex(s.sii.revision, 8)}, {"serial", s.sii.serial}, {"name", s.sii.device_name}},
         "slave " + std::to_string(s.position) + " (station " + hex(s.station, 4) + "): " + s.sii.device_name +
             ", vendor " + hex(s.sii.vendor_id, 8) + ", product " + hex(s.sii.product_code, 8) + ", revision " +
             hex(s.sii.revision, 8) + ", serial " + std::to_string(s.sii.serial));
  }
  if (!m.bring_to_operational()) {
    err << "cia402 master: " << m.error() << "\n";
    return failed;
  }
  line({{"event", "operational"}, {"slaves", slaves.size()}, {"working_counter", m.expected_working_counter()},
        {"cycle_us", m.cycle_us()}},
       "line in OP: LRW every " + std::to_string(m.cycle_us()) + " us, working counter " +
           std::to_string(m.expected_working_counter()));
  for (const auto& s : slaves) {
    line({{"event", "mapping"}, {"position", s.position}, {"source", s.mapping_source},
          {"output_bytes", s.output_bytes}, {"input_bytes", s.input_bytes}},
         "slave " + std::to_string(s.position) + ": " + std::to_string(s.output_bytes) + " bytes out, " +
             std::to_string(s.input_bytes) + " bytes in (" + s.mapping_source + ")");
  }

  std::vector<std::size_t> chosen;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    if (!a.position || static_cast<int>(i) == *a.position) chosen.push_back(i);
  }
  ecat_stop = 0;
  struct sigaction action {};
  action.sa_handler = request_ecat_master_stop;
  sigemptyset(&action.sa_mask);
  struct sigaction old_int {}, old_term {};
  sigaction(SIGINT, &action, &old_int);
  sigaction(SIGTERM, &action, &old_term);

  // The cycle, kept to its period, printing every state a drive passes and every AL state change.
  std::map<std::size_t, std::optional<state>> seen;
  std::map<std::size_t, std::uint8_t> al_seen;
  std::map<std::size_t, std::size_t> emcy_shown;
  const auto show_emergencies = [&](std::size_t i) {
    const auto& list = slaves[i].emergencies;
    for (std::size_t k = emcy_shown[i]; k < list.size(); ++k) {
      line({{"event", "emcy"}, {"position", i}, {"error_code", hex(list[k], 4)}},
           "slave " + std::to_string(i) + ": EMCY " + hex(list[k], 4) + (list[k] == 0 ? " (error reset)" : ""));
    }
    emcy_shown[i] = list.size();
  };
  for (std::size_t i : chosen) al_seen[i] = slaves[i].al_state;
  std::uint64_t next = link.now_us();
  const auto describe = [&](std::size_t i) {
    const auto& s = slaves[i];
    state st = state::start;
    const bool known = decode_status(p, s.last_status, st);
    std::string text = "slave " + std::to_string(i) + ": " + (known ? state_name(st) : "UNKNOWN") + " (statusword " +
                       word(s.last_status) + ")";
    if (s.last_error_code != 0) text += ", error code " + hex(s.last_error_code, 4);
    return text;
  };
  const auto state_json = [&](std::size_t i, const char* event) {
    const auto& s = slaves[i];
    state st = state::start;
    const bool known = decode_status(p, s.last_status, st);
    return nlohmann::ordered_json{{"event", event}, {"position", i},
                                  {"state", known ? nlohmann::ordered_json(state_name(st)) : nullptr},
                                  {"statusword", word(s.last_status)}, {"error_code", hex(s.last_error_code, 4)}};
  };
  const auto run_cycle = [&] {
    (void)m.cycle();
    for (std::size_t i : chosen) {
      state st = state::start;
      const std::optional<state> now =
          decode_status(p, slaves[i].last_status, st) ? std::optional<state>(st) : std::nullopt;
      if (seen.count(i) != 0 && seen[i] != now) line(state_json(i, "state"), describe(i));
      seen[i] = now;
      show_emergencies(i);
      if (slaves[i].al_state != al_seen[i]) {
        al_seen[i] = slaves[i].al_state;
        line({{"event", "al_state"}, {"position", i}, {"al_state", ethercat::line_state_name(slaves[i].al_state)},
              {"al_status_code", hex(slaves[i].al_code, 4)}},
             "slave " + std::to_string(i) + ": AL state " + ethercat::line_state_name(slaves[i].al_state) +
                 (slaves[i].al_code != 0 ? std::string(", AL status code ") + hex(slaves[i].al_code, 4) + " (" +
                                               ethercat::al_status_code_text(slaves[i].al_code) + ")"
                                         : std::string()));
      }
    }
    next += m.cycle_us();
    const std::uint64_t now = link.now_us();
    if (next > now) {
      link.wait_us(static_cast<std::uint32_t>(next - now));
    } else {
      next = now;  // late: go on from here rather than rush to catch up
    }
  };
  // A few cycles so every drive's inputs are in and the first state is known.
  for (int i = 0; i < 3; ++i) run_cycle();
  for (std::size_t i : chosen) {
    state st = state::start;
    if (decode_status(p, slaves[i].last_status, st)) seen[i] = st;
  }

  int status = 0;
  const std::uint64_t timeout_us = a.timeout_ms * 1000ull;
  // Runs cycles until done() says every chosen drive is through, a signal, or the time limit.
  const auto cycle_until = [&](const std::function<bool()>& done, const char* what) {
    const std::uint64_t start = link.now_us();
    while (!done()) {
      if (ecat_stop != 0) {
        err << "cia402 master: interrupted\n";
        return false;
      }
      if (timeout_us != 0 && link.now_us() - start > timeout_us) {
        err << "cia402 master: " << what << " did not finish within " << a.timeout_ms << " ms\n";
        return false;
      }
      run_cycle();
    }
    return true;
  };
  const auto observed = [&](std::size_t i) {
    state st = state::start;
    return decode_status(p, slaves[i].last_status, st) ? st : state::start;
  };

  for (const step& s : *steps) {
    if (status != 0) break;
    if (s.what == "state") {
      for (std::size_t i : chosen) line(state_json(i, "status"), describe(i));
    } else if (s.what == "enable" || s.what == "disable" || s.what == "reset") {
      const state target = s.what == "enable" ? state::operation_enabled : state::switch_on_disabled;
      std::vector<std::size_t> acting;
      for (std::size_t i : chosen) {
        const state now = observed(i);
        if (s.what == "reset" && now != state::fault && now != state::fault_reaction_active) {
          line(state_json(i, "nothing_to_reset"), describe(i) + ": not in FAULT, nothing to reset");
          continue;
        }
        m.set_target(i, target);
        acting.push_back(i);
      }
      std::string failure;
      const bool ok = cycle_until(
          [&] {
            for (std::size_t i : acting) {
              const master_outcome o = slaves[i].steering.outcome();
              if (o == master_outcome::reached) continue;
              if (o == master_outcome::fault || o == master_outcome::timed_out || o == master_outcome::unreachable ||
                  o == master_outcome::not_remote) {
                failure = describe(i) + ": " + master_outcome_name(o);
                if (o == master_outcome::timed_out && observed(i) == state::fault) {
                  failure += "; is the fault cause still present?";
                }
                return true;
              }
              return false;
            }
            return true;
          },
          s.what.c_str());
      if (!ok || !failure.empty()) {
        if (!failure.empty()) err << "cia402 master: " << s.what << ": " << failure << "\n";
        status = failed;
        break;
      }
      for (std::size_t i : acting) line(state_json(i, "reached"), describe(i) + ": reached");
    } else if (s.what == "quick-stop") {
      // Done when each stop has ended as its 0x605A says (S5): 1..4 in SWITCH ON DISABLED, 5..8 in
      // QUICK STOP ACTIVE at standstill (bit 10), 0 in QUICK STOP ACTIVE.
      std::map<std::size_t, std::int64_t> code;
      for (std::size_t i : chosen) {
        const auto r = m.sdo_read(i, 0x605A, 0);
        code[i] = r.ok ? r.value(true) : 2;
        m.hold_command(i, command::quick_stop);
      }
      const bool ok = cycle_until(
          [&] {
            for (std::size_t i : chosen) {
              const state st = observed(i);
              const bool held = st == state::quick_stop_active &&
                                (code[i] == 0 || (code[i] >= 5 && (slaves[i].last_status & status_bit::target_reached)));
              if (!held && st != state::switch_on_disabled) return false;
            }
            return true;
          },
          "quick-stop");
      if (!ok) {
        status = failed;
        break;
      }
      for (std::size_t i : chosen) line(state_json(i, "quick_stop_done"), describe(i) + ": quick stop done");
    } else if (s.what == "wait") {
      const std::uint64_t start = link.now_us();
      while (ecat_stop == 0 && link.now_us() - start < static_cast<std::uint64_t>(s.value) * 1000) run_cycle();
    } else if (s.what == "watch") {
      for (std::size_t i : chosen) m.release(i);
      const std::uint64_t start = link.now_us();
      while (ecat_stop == 0 && (timeout_us == 0 || link.now_us() - start < timeout_us)) run_cycle();
    } else {  // sdo-read, sdo-write
      const object_description* known = find_drive_object(s.index, s.sub);
      const unsigned bytes = known != nullptr ? static_cast<unsigned>(type_size(known->type)) : 4u;
      const bool is_signed = known != nullptr && type_signed(known->type);
      const std::string object = hex(s.index, 4) + ":" + std::to_string(s.sub);
      for (std::size_t i : chosen) {
        const bool writing = s.what == "sdo-write";
        // Between SDOs the process data keeps flowing, so the watchdog never sees a gap.
        run_cycle();
        ethercat::ecat_sdo_result r =
            writing ? m.sdo_write(i, s.index, s.sub, s.value, bytes) : m.sdo_read(i, s.index, s.sub);
        // An object the CiA 402 table does not know goes as 4 bytes; when the drive says that is
        // too long, as 2, then 1 (its size is what it accepts).
        for (unsigned shorter = 2; writing && known == nullptr && !r.ok && shorter >= 1 &&
                                   r.abort == sdo_abort::data_type_length_too_high;
             shorter /= 2) {
          r = m.sdo_write(i, s.index, s.sub, s.value, shorter);
        }
        if (!r.ok) {
          err << "cia402 master: " << r.error << "\n";
          status = failed;
          break;
        }
        const std::int64_t v = writing ? s.value : r.value(is_signed);
        line({{"event", writing ? "sdo_written" : "sdo"}, {"position", i}, {"object", object}, {"value", v}},
             "slave " + std::to_string(i) + ": " + object + (writing ? " written: " : " = ") + std::to_string(v) +
                 " (" + hex(static_cast<std::uint64_t>(v) & 0xFFFFFFFFull, 2 * static_cast<int>(bytes)) + ")");
      }
    }
  }
  if (status == 0 && a.hold) {
    while (ecat_stop == 0) run_cycle();
  }
  for (std::size_t i : chosen) show_emergencies(i);
  line({{"event", "done"}, {"cycles", m.cycles()}, {"lost_frames", m.lost_frames()}},
       "done after " + std::to_string(m.cycles()) + " cycles, " + std::to_string(m.lost_frames()) +
           " frame(s) lost; the drives now see the master go (SM watchdog) and act as 0x6007 says");
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  return status;
}

}  // namespace cia402::cli
