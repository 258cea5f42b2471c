#pragma once
// One table of every run parameter: the CLI flags, config files and report.json all read it,
// so a parameter is declared once. Keys are snake_case; the flag is the key with dashes
// (`mls_radius` <-> `--mls-radius`). All lengths are metres whatever `--units` says.

#include <groovetrace/params.hpp>

#include <functional>
#include <string>
#include <vector>

namespace groovetrace {

struct ParamSpec {
  std::string key;   ///< snake_case name in config files and report.json
  std::string help;  ///< one line for --help, with unit
  /// Parses a textual value into params; throws UsageError("<key>: ...") when invalid.
  std::function<void(Params&, const std::string&)> set;
  /// The current value as a JSON literal (number, string, bool, array or null).
  std::function<std::string(const Params&)> json;
};

/// Every parameter, in documentation order.
const std::vector<ParamSpec>& param_specs();

/// Sets one parameter by key (dashes accepted for underscores). Throws UsageError for an
/// unknown key or an invalid value.
void set_param(Params& params, const std::string& key, const std::string& value);

/// Applies a YAML (.yaml/.yml) or JSON (.json) config file: a flat map of key: value.
/// Throws InputError if the file cannot be read or parsed, UsageError for unknown keys or
/// invalid values (the message names the file and key).
void apply_config_file(Params& params, const std::string& path);

/// All parameters as one JSON object (text).
std::string params_json(const Params& params);

}  // namespace groovetrace
