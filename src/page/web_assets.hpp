// The page's files, embedded in the binary at build time (web_assets.cpp is generated from web/ by
// embed_web.cmake), so `cia402 serve` needs nothing beside itself.
#pragma once

#include <cstddef>
#include <span>

namespace cia402::page::web {

struct asset {
  const char* path;          ///< "/index.html"
  const char* content_type;  ///< "text/html; charset=utf-8"
  const unsigned char* data;
  std::size_t size;
};

std::span<const asset> assets() noexcept;

}  // namespace cia402::page::web
