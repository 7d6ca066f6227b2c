// The `cia402` tool; everything it does lives in cia402_cli_lib (cli/app.hpp).
#include <iostream>
#include <string>
#include <vector>

#include "cli/app.hpp"

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  const std::vector<std::string> args(argv + 1, argv + argc);
  return cia402::cli::run(args, std::cin, std::cout, std::cerr);
}
