#include "cli/diagram.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

#include "cia402/diagram.hpp"

namespace cia402::cli {
namespace {

// Graphviz renders the SVG; a temporary directory holds its input and output.
int render_svg(const std::string& dot, std::ostream& out, std::ostream& err) {
  if (std::system("command -v dot >/dev/null 2>&1") != 0) {
    err << "cia402 diagram: --format svg needs Graphviz's `dot`, which is not installed "
           "(Debian: apt-get install graphviz); --format dot or mermaid work without it\n";
    return 1;
  }
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::temp_directory_path(ec) /
                       ("cia402-diagram-" + std::to_string(static_cast<long>(::getpid())));
  fs::create_directories(dir, ec);
  if (ec) {
    err << "cia402 diagram: cannot create a temporary directory: " << ec.message() << "\n";
    return 1;
  }
  const fs::path in = dir / "diagram.dot";
  const fs::path svg = dir / "diagram.svg";
  std::ofstream(in) << dot;
  const std::string command = "dot -Tsvg '" + in.string() + "' -o '" + svg.string() + "'";
  const int status = std::system(command.c_str());
  std::ifstream result(svg);
  std::stringstream text;
  text << result.rdbuf();
  fs::remove_all(dir, ec);
  if (status != 0 || text.str().empty()) {
    err << "cia402 diagram: Graphviz failed to render the diagram\n";
    return 1;
  }
  out << text.str();
  return 0;
}

}  // namespace

int run_diagram(const profile& p, const std::string& format, std::ostream& out, std::ostream& err) {
  if (format == "dot") {
    out << diagram_dot(p);
    return 0;
  }
  if (format == "mermaid") {
    out << diagram_mermaid(p);
    return 0;
  }
  if (format == "svg") return render_svg(diagram_dot(p), out, err);
  err << "cia402 diagram: unknown format '" << format << "' (dot, mermaid, svg)\n";
  return 2;
}

}  // namespace cia402::cli
