// Putting a node back as the link found it: every object the set-up wrote, recorded before it was
// written, is written back in reverse order. A PDO is made invalid first (CiA 301 §7.5.2.35: its
// mapping changes only while the PDO is invalid and its count is 0), then its mapping entries and
// count, its other communication parameters, and last its COB-ID as it was (valid or not).
#include <algorithm>
#include <deque>
#include <map>

#include "cia402/canopen/301/slave.hpp"
#include "cia402/canopen/axis/can_link.hpp"
#include "cia402/support/text.hpp"

namespace cia402::canopen {
namespace {

using support::hex;

bool pdo_communication(std::uint16_t index) {
  return (index >= 0x1400 && index <= 0x15FF) || (index >= 0x1800 && index <= 0x19FF);
}
bool pdo_mapping(std::uint16_t index) {
  return (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
}
// The communication index a PDO is known by.
std::uint16_t pdo_of(std::uint16_t index) { return pdo_mapping(index) ? static_cast<std::uint16_t>(index - 0x200) : index; }

// What the master restores is CiA 301's communication objects: their names are any node's.
std::string name_of(std::uint16_t index) {
  static const std::vector<dictionary::object_entry> table = communication_objects(slave_config{});
  for (const dictionary::object_entry& o : table) {
    if (o.index == index) return hex(index, 4) + " (" + o.name + ")";
  }
  return hex(index, 4);
}

}  // namespace

std::vector<can_link::recorded> can_link::restore_order() const {
  std::vector<recorded> out;
  // The PDOs in the reverse order of their first write, each as one sequence.
  std::vector<std::uint16_t> pdos;
  for (const recorded& r : recorded_) {
    if (!pdo_communication(r.index) && !pdo_mapping(r.index)) continue;
    const std::uint16_t p = pdo_of(r.index);
    if (std::find(pdos.begin(), pdos.end(), p) == pdos.end()) pdos.push_back(p);
  }
  const auto find = [this](std::uint16_t index, std::uint8_t sub) -> const recorded* {
    for (const recorded& r : recorded_) {
      if (r.index == index && r.sub == sub && !r.bytes.empty()) return &r;
    }
    return nullptr;
  };
  for (auto p = pdos.rbegin(); p != pdos.rend(); ++p) {
    const std::uint16_t comm = *p;
    const auto map = static_cast<std::uint16_t>(comm + 0x200);
    const recorded* cob = find(comm, 1);
    if (cob != nullptr && cob->bytes.size() == 4) {
      recorded invalid = *cob;
      invalid.bytes[3] = static_cast<std::uint8_t>(invalid.bytes[3] | 0x80);  // bit 31: not valid
      out.push_back(invalid);
    }
    const recorded* count = find(map, 0);
    if (count != nullptr) out.push_back({map, 0, {0}});
    for (const recorded& r : recorded_) {
      if (r.index == map && r.sub != 0 && !r.bytes.empty()) out.push_back(r);
    }
    if (count != nullptr) out.push_back(*count);
    for (const recorded& r : recorded_) {
      if (r.index == comm && r.sub != 1 && !r.bytes.empty()) out.push_back(r);
    }
    if (cob != nullptr) out.push_back(*cob);
  }
  // Then the rest (0x1016, 0x1017), last written first.
  for (auto r = recorded_.rbegin(); r != recorded_.rend(); ++r) {
    if (!pdo_communication(r->index) && !pdo_mapping(r->index) && !r->bytes.empty()) out.push_back(*r);
  }
  return out;
}

void can_link::close() {
  if (stage_ == stage::closed || stage_ == stage::restoring) return;
  word_.reset();
  // Every transfer still queued in the link (the one under way too; in the cyclic stage those held
  // while the node is STOPPED) ends now, cancelled: its caller would wait for it otherwise for ever,
  // as a closed link polls no more.
  if (own_busy_) sdo_.cancel();
  own_busy_ = false;
  std::deque<transfer> queued;
  queued.swap(own_);
  if (stage_ == stage::acyclic || stage_ == stage::recording) {
    finish_close();  // nothing was set up: nothing to put back
  } else {
    stage_ = stage::restoring;
    restoring_ = restore_order();
    restore_at_ = 0;
    restore_busy_ = false;
    if (sdo_held_) {
      // A node this link stopped answers no SDO: said once per object, not found out by a time-out each.
      std::vector<std::uint16_t> objects;
      for (const recorded& r : restoring_) {
        if (std::find(objects.begin(), objects.end(), r.index) != objects.end()) continue;
        objects.push_back(r.index);
        report_.left.push_back(name_of(r.index) + " not put back: " + short_name() + " is STOPPED (NMT stop)");
      }
      restore_at_ = restoring_.size();
    }
  }
  axes::cancel_transfers(queued, short_name() + ": the link was closed before the transfer ended");
}

void can_link::restore_next() {
  if (restore_busy_) return;
  if (restore_at_ < restoring_.size() && master_->phase() != master_phase::running) {
    const std::string why = master_->failure_text();
    for (; restore_at_ < restoring_.size(); ++restore_at_) {
      const recorded& r = restoring_[restore_at_];
      report_.left.push_back(hex(r.index, 4) + ":" + std::to_string(r.sub) + " not put back: " + why);
    }
  }
  if (restore_at_ >= restoring_.size()) return finish_close();
  const recorded r = restoring_[restore_at_];
  restore_busy_ = master_->download(r.index, r.sub, r.bytes, [this, r](const sdo_result& result) {
    restore_busy_ = false;
    ++restore_at_;
    if (!result.ok()) {
      report_.left.push_back(hex(r.index, 4) + ":" + std::to_string(r.sub) + " not put back: " +
                             (result.cancelled ? std::string("the link was lost")
                                               : "SDO abort " + hex(static_cast<std::uint32_t>(result.abort), 8) + " (" +
                                                     sdo_abort_text(result.abort) + ")"));
    }
  });
  if (!restore_busy_) ++restore_at_;
}

void can_link::finish_close() {
  std::vector<std::uint16_t> objects;
  for (const recorded& r : restoring_) {
    if (std::find(objects.begin(), objects.end(), r.index) == objects.end()) objects.push_back(r.index);
  }
  for (std::uint16_t index : objects) {
    const std::string entry = hex(index, 4) + ":";
    const std::string object = name_of(index) + " ";
    const bool refused = std::any_of(report_.left.begin(), report_.left.end(), [&](const std::string& l) {
      return l.rfind(entry, 0) == 0 || l.rfind(object, 0) == 0;
    });
    if (!refused) report_.restored.push_back(name_of(index));
  }
  if (master_ && stage_ == stage::restoring) {
    if (sdo_held_) {
      report_.left.push_back("NMT state STOPPED, as NMT stop left it");
    } else if (pdos_quiet_ && !start_sent_) {
      report_.left.push_back("NMT state PRE-OPERATIONAL, as NMT preop left it");
    } else {
      report_.left.push_back("NMT state OPERATIONAL: this master started the node (the state before is not known)");
    }
    master_->clear_target();
  }
  report_.done = true;
  stage_ = stage::closed;
}

}  // namespace cia402::canopen
