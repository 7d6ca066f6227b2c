// The page's object writes and parameter routes (docs/instrument-page.md, "Parameter list and
// parameter files"): POST /api/object by INDEX:SUB, GET /api/parameters, GET and POST
// /api/parameters.dcf. Split from server.cpp, whose checks they pass through (parameter_route_hooks).
#include <cstdio>
#include <string>

#include "server_http.hpp"

namespace cia402::page::detail {
namespace {

using json = nlohmann::json;

void send_document(httplib::Response& res, const document& d) {
  res.status = d.http_status;
  res.set_content(d.body, "application/json");
}

}  // namespace

void send_refusal(httplib::Response& res, const refused& no) {
  json j{{"error", no.reason}};
  if (no.abort != sdo_abort::none) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%08X", static_cast<unsigned>(no.abort));
    j["abort"] = buf;
    j["abort_text"] = sdo_abort_text(no.abort);
  }
  send_json(res, no.http_status, j);
}

std::variant<reply, request_error> object_request(backend& drive, const json& body) {
  if (auto k = unknown_key(body, {"index", "value"})) return request_error{400, *k};
  if (!body.contains("index") || !body.contains("value")) {
    return request_error{400, "'index' and 'value' are required"};
  }
  // "0x6099:1": the index, then the sub-index (decimal or 0x-hexadecimal); a bare index is sub 0.
  const json& given = body["index"];
  std::optional<std::int64_t> index, sub = 0;
  if (given.is_string() && given.get_ref<const std::string&>().find(':') != std::string::npos) {
    const std::string& s = given.get_ref<const std::string&>();
    const auto colon = s.find(':');
    index = integer_of(json(s.substr(0, colon)));
    sub = integer_of(json(s.substr(colon + 1)));
  } else {
    index = integer_of(given);
  }
  if (!index || *index < 0 || *index > 0xFFFF || !sub || *sub < 0 || *sub > 0xFF) {
    return request_error{400, "'index' must be an object index 0x0000..0xFFFF, or INDEX:SUB (\"0x6099:1\")"};
  }
  const json& value = body["value"];
  const auto i = static_cast<std::uint16_t>(*index);
  if (value.is_string()) {
    return drive.write_entry(i, static_cast<std::uint8_t>(*sub), value.get_ref<const std::string&>());
  }
  const auto number = value.is_number() ? integer_of(value) : std::nullopt;
  if (!number) return request_error{400, "'value' must be an integer, or a string"};
  if (*sub == 0) return drive.write_object(i, *number);
  return drive.write_entry(i, static_cast<std::uint8_t>(*sub), std::to_string(*number));
}

void add_parameter_routes(httplib::Server& http, parameter_route_hooks hooks) {
  http.Get("/api/parameters", [hooks](const httplib::Request& req, httplib::Response& res) {
    if (backend* drive = hooks.axis_of(req, res)) send_document(res, drive->parameters());
  });
  http.Get(parameter_file_path, [hooks](const httplib::Request& req, httplib::Response& res) {
    backend* drive = hooks.axis_of(req, res);
    if (drive == nullptr) return;
    const document d = drive->parameter_file();
    if (d.http_status != 200) return send_document(res, d);
    res.set_header("Content-Disposition", "attachment; filename=\"cia402-parameters.dcf\"");
    res.set_content(d.body, "text/plain");
  });
  // The file travels in a JSON body ({"file": "<the file's text>"}), so it passes the checks every
  // control request passes (token, origin, Content-Type).
  http.Post(parameter_file_path, [hooks](const httplib::Request& req, httplib::Response& res) {
    auto body = hooks.post_body(req, res);
    if (!body) return;
    const json& b = body->second;
    if (auto k = unknown_key(b, {"file"})) return send_error(res, 400, *k);
    if (!b.contains("file") || !b["file"].is_string()) {
      return send_error(res, 400, "'file' (the parameter file's text) is required");
    }
    send_document(res, body->first->load_parameter_file(b["file"].get_ref<const std::string&>()));
  });
  http.Get("/api/object", [](const httplib::Request&, httplib::Response& res) {
    send_error(res, 405, "use POST with a JSON body");
  });
}

}  // namespace cia402::page::detail
