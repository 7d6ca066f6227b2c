#include "json_text.hpp"

#include "cia402/support/text.hpp"

namespace cia402::page::detail {

bool is_utf8(std::string_view s) { return support::is_utf8(s); }

}  // namespace cia402::page::detail
