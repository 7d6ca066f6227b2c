// socketcand elements as a client sends them: the reader splits any bytes into elements of at most
// its bound, and a `send` element is parsed into a frame or refused with a reason; a parsed frame
// formats back to an element that parses to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "cia402/canopen/transport/socketcand.hpp"

using namespace cia402::canopen;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  socketcand::element_reader reader(256);
  reader.feed(std::string_view(reinterpret_cast<const char*>(data), size));
  std::string element;
  for (;;) {
    const auto r = reader.next(element);
    if (r == socketcand::element_reader::result::none) break;
    if (r == socketcand::element_reader::result::too_long) continue;
    if (element.size() > 256) std::abort();
    frame f;
    std::string why;
    if (!socketcand::parse_send(element, f, why)) {
      if (why.empty()) std::abort();
      continue;
    }
    // "< frame ID T DATA >" -> "< send ID LEN BYTES >", which must parse to the same frame.
    std::string again = "< send " + std::to_string(0) + " >";
    const std::string formatted = socketcand::format_frame(f, 0);
    const auto w = socketcand::words(formatted);
    if (w.size() < 3) std::abort();
    again = "< send " + std::string(w[1]) + " " + std::to_string(f.len);
    const std::string_view hex = w.size() > 3 ? w[3] : std::string_view();
    for (std::size_t k = 0; k + 1 < hex.size(); k += 2) again += " " + std::string(hex.substr(k, 2));
    again += " >";
    frame g;
    if (!socketcand::parse_send(again, g, why) || g.id != f.id || g.len != f.len) std::abort();
    for (std::uint8_t k = 0; k < f.len; ++k) {
      if (g.data[k] != f.data[k]) std::abort();
    }
  }
  return 0;
}
