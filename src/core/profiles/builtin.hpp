// The built-in profiles, one translation unit each.
#pragma once

#include "cia402/profile.hpp"

namespace cia402::detail {

extern const profile cia402_profile;
extern const profile no_quick_stop_profile;
extern const profile lexium32_profile;
extern const profile s300_profibus_profile;
extern const profile ax2000_profibus_profile;

}  // namespace cia402::detail
