#include "cia402/axis/drive_link.hpp"

#include <utility>

namespace cia402::axes {

bool link_base::upload(std::uint16_t index, std::uint8_t sub, transfer_done done) {
  if (phase() != link_phase::running) return false;
  return queue_transfer({index, sub, false, {}, std::move(done)});
}

bool link_base::download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                         transfer_done done) {
  if (phase() != link_phase::running) return false;
  return queue_transfer({index, sub, true, std::move(bytes), std::move(done)});
}

void cancel_transfers(std::deque<pending_transfer>& queue, const std::string& why) {
  transfer_result r;
  r.cancelled = true;
  r.error = why;
  std::deque<pending_transfer> gone;
  gone.swap(queue);
  for (pending_transfer& t : gone) {
    if (t.done) t.done(r);
  }
}

}  // namespace cia402::axes
