#pragma once
// One table of every run parameter: the CLI flags, config files and report.json all read it,
// so a parameter is declared once. Keys are snake_case; the flag is the key with dashes
// (`mls_radius` <-> `--mls-radius`). All lengths are metres whatever `--units` says.

#include <functional>
#include <groovetrace/params.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// Which method a parameter belongs to.
enum class ParamScope { common, paper, robust };

struct GT_API ParamSpec {
  std::string key;   ///< snake_case name in config files and report.json
  std::string help;  ///< one line for --help, with unit
  ParamScope scope = ParamScope::common;
  /// Parses a textual value into params; throws UsageError("<key>: ...") when invalid.
  std::function<void(Params&, const std::string&)> set;
  /// The current value as a JSON literal (number, string, bool, array or null).
  std::function<std::string(const Params&)> json;
  /// Back to "not given" (the default), for a null in a config file; empty when the
  /// parameter has no such state (a null is then refused).
  std::function<void(Params&)> unset = nullptr;
  /// A file path: in a config file, relative to the config file's folder.
  bool file_path = false;
  /// A switch that is off by default: on the command line a flag without a value
  /// (`--dry-run` sets "true"); in a config file `key: true` or `key: false`.
  bool flag = false;
};

/// Every parameter, in documentation order.
GT_API const std::vector<ParamSpec>& param_specs();

/// Sets one parameter by key (dashes accepted for underscores). Throws UsageError for an
/// unknown key or an invalid value.
GT_API void set_param(Params& params, const std::string& key, const std::string& value);

/// Applies a YAML (.yaml/.yml) or JSON (.json) config file: a flat map of key: value, or a
/// report.json (its `parameters` object is read). A null value is the parameter's "not
/// given" (viewpoint, slices, hand_eye, flange_pose); a relative file path is taken from the
/// config file's folder. Throws InputError if the file cannot be read or parsed, UsageError
/// for unknown keys or invalid values (the message names the file and key). Returns the keys
/// it set to something other than their default (for other_method_warning: report.json
/// lists every key, the other method's at their defaults).
GT_API std::vector<std::string> apply_config_file(Params& params, const std::string& path);

/// A warning when `key` belongs to the method that `params` does not run (e.g. `radius`
/// under the robust method), naming both; empty when the key is common or the method's own.
GT_API std::string other_method_warning(const Params& params, const std::string& key);

/// All parameters as one JSON object (text): what a config file takes back to run the same
/// (file paths absolute; `slices` the chosen method's, null for the robust method's step).
GT_API std::string params_json(const Params& params);

}  // namespace groovetrace
