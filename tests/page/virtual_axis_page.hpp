// The page's drive as `cia402 serve` builds it without a bus: an axis page over apps::local_link, a
// virtual drive in this process whose plant inputs the page sets through the simulator.
#pragma once

#include <memory>
#include <utility>

#include "cia402/apps/local_link.hpp"
#include "cia402/page/axis_page.hpp"

namespace cia402::page::testing {

inline drive_connection virtual_connection(const profile& p) {
  auto link = std::make_unique<apps::local_link>(p);
  sim::virtual_drive* plant = &link->drive();
  return {std::move(link), plant};
}

class virtual_axis_page : public axis_page {
 public:
  explicit virtual_axis_page(const profile& p, axis_page_config c = {})
      : axis_page(p, virtual_connection, std::move(c)) {}
};

}  // namespace cia402::page::testing
