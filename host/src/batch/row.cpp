#include "batch/row.hpp"

#include <cstdio>
#include <fstream>
#include <groovetrace/error.hpp>
#include <nlohmann/json.hpp>

namespace groovetrace::batch {
namespace {

using nlohmann::json;

std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::string row_json(const ScanRow& r) {
  json stages = json::array();
  for (const auto& [name, ms] : r.stages_ms) stages.push_back({name, ms});
  const json j = {{"scan", r.scan},
                  {"dir", r.dir},
                  {"status", r.status},
                  {"exit_code", r.exit_code},
                  {"message", r.message},
                  {"points", r.points},
                  {"valid_points", r.valid_points},
                  {"groove_points", r.groove_points},
                  {"seams", r.seams},
                  {"exported", r.exported},
                  {"waypoints", r.waypoints},
                  {"length_m", r.length_m},
                  {"stages_ms", stages},
                  {"total_ms", r.total_ms},
                  {"input_hash", r.input_hash},
                  {"params_hash", r.params_hash}};
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

ScanRow row_from_json(const std::string& text, const std::string& where) {
  try {
    const json j = json::parse(text);
    ScanRow r;
    r.scan = j.at("scan").get<std::string>();
    r.dir = j.at("dir").get<std::string>();
    r.status = j.at("status").get<std::string>();
    r.exit_code = j.at("exit_code").get<int>();
    r.message = j.at("message").get<std::string>();
    r.points = j.at("points").get<std::size_t>();
    r.valid_points = j.at("valid_points").get<std::size_t>();
    r.groove_points = j.at("groove_points").get<std::size_t>();
    r.seams = j.at("seams").get<int>();
    r.exported = j.at("exported").get<int>();
    r.waypoints = j.at("waypoints").get<std::size_t>();
    r.length_m = j.at("length_m").get<double>();
    for (const auto& s : j.at("stages_ms")) {
      r.stages_ms.emplace_back(s.at(0).get<std::string>(), s.at(1).get<double>());
    }
    r.total_ms = j.at("total_ms").get<double>();
    r.input_hash = j.at("input_hash").get<std::string>();
    r.params_hash = j.at("params_hash").get<std::string>();
    return r;
  } catch (const std::exception& e) {
    throw InputError(where + " is not a scan row: " + e.what());
  }
}

std::string csv_header() {
  return "scan,dir,status,exit_code,message,points,valid_points,groove_points,seams,exported,"
         "waypoints,length_m,total_ms,stages_ms,input_hash,params_hash\n";
}

std::string csv_line(const ScanRow& r) {
  std::string stages;
  for (const auto& [name, ms] : r.stages_ms) {
    stages += (stages.empty() ? "" : ";") + name + "=" + number(ms);
  }
  return csv_cell(r.scan) + "," + csv_cell(r.dir) + "," + r.status + "," +
         std::to_string(r.exit_code) + "," + csv_cell(r.message) + "," + std::to_string(r.points) +
         "," + std::to_string(r.valid_points) + "," + std::to_string(r.groove_points) + "," +
         std::to_string(r.seams) + "," + std::to_string(r.exported) + "," +
         std::to_string(r.waypoints) + "," + number(r.length_m) + "," + number(r.total_ms) + "," +
         csv_cell(stages) + "," + r.input_hash + "," + r.params_hash + "\n";
}

std::uint64_t fnv1a64(const char* data, std::size_t size, std::uint64_t seed) {
  std::uint64_t h = seed;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

std::string hex64(std::uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

std::string file_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read " + path);
  std::uint64_t h = 14695981039346656037ull;
  std::string chunk(1 << 20, '\0');
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    h = fnv1a64(chunk.data(), static_cast<std::size_t>(in.gcount()), h);
  }
  return hex64(h);
}

}  // namespace groovetrace::batch
