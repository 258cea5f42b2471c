#include "param_flags.hpp"

#include <algorithm>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>
#include <groovetrace/program.hpp>
#include <nlohmann/json.hpp>

namespace groovetrace::cli {

std::string dashed(std::string key) {
  for (char& c : key) {
    if (c == '_') c = '-';
  }
  return key;
}

namespace {

// " [default: 0.008]": a default Params' value as report.json shows it, strings bare; "none"
// for a parameter not set by default.
std::string default_note(const ParamSpec& spec) {
  const auto j = nlohmann::json::parse(spec.json(Params()));
  const std::string text = j.is_null() ? "" : j.is_string() ? j.get<std::string>() : j.dump();
  return " [default: " + (text.empty() ? std::string("none") : text) + "]";
}

}  // namespace

void add_param_flags(CLI::App* sub, const std::shared_ptr<ParamFlags>& given) {
  sub->add_option("--config", given->config,
                  "YAML or JSON file of parameters, or a report.json (flags win)");
  for (const auto& spec : param_specs()) {
    const std::string key = spec.key;
    if (spec.flag) {  // a switch: given means on, and it takes no value
      sub->add_flag_function(
             "--" + dashed(key), [given, key](std::int64_t) { given->flags[key] = "true"; },
             spec.help + default_note(spec))
          // "--key=value" is refused as a usage error: CLI11 converted "perhaps" with stoll and
          // its std::invalid_argument aborted the program.
          ->disable_flag_override();
      continue;
    }
    sub->add_option_function<std::string>(
        "--" + dashed(key), [given, key](const std::string& v) { given->flags[key] = v; },
        spec.help + default_note(spec));
  }
}

Params parse_params(const ParamFlags& given, std::vector<std::string>& warnings) {
  Params params;
  std::vector<std::string> keys;
  if (!given.config.empty()) keys = apply_config_file(params, given.config);
  for (const auto& [key, text] : given.flags) {
    try {
      set_param(params, key, text);
    } catch (const UsageError& e) {
      throw UsageError("--" + dashed(key) + ": " + std::string(e.what()).substr(key.size() + 2));
    }
    keys.push_back(key);
  }
  validate(params);
  // Settings that depend on each other (the arc output of --robot) fail here, before the run.
  check_program_params(params.program);
  for (const std::string& key : keys) {
    const std::string w = other_method_warning(params, key);
    if (!w.empty() && std::find(warnings.begin(), warnings.end(), w) == warnings.end()) {
      warnings.push_back(w);
    }
  }
  return params;
}

}  // namespace groovetrace::cli
