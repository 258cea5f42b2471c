#pragma once
// The run parameters as flags and a config file, shared by `run` and `batch`.

#include <CLI/CLI.hpp>
#include <groovetrace/params.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace groovetrace::cli {

/// What the user gave: the config file and the parameter flags (key -> text).
struct ParamFlags {
  std::string config;
  std::map<std::string, std::string> flags;
};

/// Adds --config and one flag per parameter (param_specs()) to `sub`.
void add_param_flags(CLI::App* sub, const std::shared_ptr<ParamFlags>& given);

/// The config file, then the flags, validated; a warning per key that the chosen method
/// ignores. Throws UsageError naming the flag, InputError for an unreadable config.
Params parse_params(const ParamFlags& given, std::vector<std::string>& warnings);

/// `key_name` -> `key-name`.
std::string dashed(std::string key);

}  // namespace groovetrace::cli
