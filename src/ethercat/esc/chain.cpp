// The in-process wire (esc.hpp): a frame through every controller in order, as a line passes it.
#include "cia402/ethercat/esc/esc.hpp"

namespace cia402::ethercat {

void chain::add(esc& e) {
  if (!escs_.empty()) escs_.back()->set_next_port_open(true);
  e.set_next_port_open(false);
  escs_.push_back(&e);
}

frame_error chain::pass(std::vector<std::uint8_t>& frame) noexcept {
  const frame_error e = parse_frame(frame, parsed_);
  if (e != frame_error::none) {
    ++refused_frames_;
    ++refused_by_[static_cast<std::size_t>(e)];
    return e;
  }
  for (esc* s : escs_) s->process(parsed_);
  ++frames_;
  return frame_error::none;
}

}  // namespace cia402::ethercat
