#include "cia402/axis/drive_link.hpp"

namespace cia402::axes {

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
