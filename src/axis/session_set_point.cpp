// Profile position's set-point offer (session::offer_set_point): the handshake of control bit 4 and
// status bit 12 (CiA 402-2 §6.2.3), run on the session's cycle rather than by its caller's polling.
#include <memory>
#include <string>

#include "cia402/axis/session.hpp"
#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {

std::uint64_t session::offer_set_point(std::uint16_t word, completion done) {
  constexpr std::uint16_t bit4 = control_bit::new_set_point;
  const auto low = static_cast<std::uint16_t>(word & ~bit4);
  auto acknowledged = std::make_shared<bool>(false);
  auto since = std::make_shared<std::uint64_t>(0);
  // The words go out as send_word's do: control::words, each answered before the next step.
  auto put = [this](std::initializer_list<std::uint16_t> words) {
    op_->commanded = true;
    control_ = control::words;
    words_.clear();
    word_changed_us_ = now_us_;
    word_changed_count_ = link_->status_count();
    for (const std::uint16_t w : words) words_.emplace_back(w, 0);
  };
  std::vector<step> steps{
      need_cyclic(),
      call_step([this, put, low] {
        // A rising edge: bit 4 down for a cycle first when the drive has it up.
        if ((sent_.value_or(0) & bit4) != 0) {
          put({low, static_cast<std::uint16_t>(low | bit4)});
        } else {
          put({static_cast<std::uint16_t>(low | bit4)});
        }
      }),
      edge_sent(),
      // Ends unacknowledged too, without failing: bit 4 must come down either way; the last step says so.
      {[this, since] { *since = now_us_; },
       [this, since, acknowledged] {
         *acknowledged = settled() && (link_->status_word() & status_bit::set_point_acknowledge) != 0;
         if (*acknowledged || now_us_ - *since >= config_.acknowledge_timeout_us) return step_state::done;
         return step_state::running;
       }},
      call_step([put, low] { put({low}); }),
      edge_sent(),
      {nullptr, [this, acknowledged] {
         if (*acknowledged) return step_state::done;
         return fail_step("no set-point acknowledge (status bit 12) within " +
                          std::to_string(config_.acknowledge_timeout_us / 1000) + " ms; bit 4 cleared");
       }},
  };
  const std::uint64_t id = begin("new set-point", std::move(steps), std::move(done), false);
  op_->fault_ok = true;
  return id;
}

}  // namespace cia402::axes
