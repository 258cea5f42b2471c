// YAML and JSON calibration files as calib::Value trees (calibration_tree.hpp).

#include "robot/calibration_tree.hpp"

#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>
#include <set>

#include "io/text.hpp"

namespace groovetrace::calib {

const Value* Value::find(const std::string& key) const {
  for (const auto& [k, v] : entries) {
    if (k == key) return &v;
  }
  return nullptr;
}

namespace {

Value from_yaml(const YAML::Node& node) {
  Value v;
  if (node.IsScalar()) {
    v.kind = Value::Kind::scalar;
    v.text = node.Scalar();
    double d = 0;
    if (YAML::convert<double>::decode(node, d)) v.number = d;
  } else if (node.IsSequence()) {
    v.kind = Value::Kind::list;
    for (const auto& item : node) v.items.push_back(from_yaml(item));
  } else if (node.IsMap()) {
    v.kind = Value::Kind::map;
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) io::reject("a map key is itself a list or map");
      const std::string key = kv.first.Scalar();
      if (v.find(key)) io::reject("key '" + io::shown(key, 100) + "' appears twice");
      v.entries.emplace_back(key, from_yaml(kv.second));
    }
  }
  return v;
}

Value from_json(const nlohmann::json& j) {
  Value v;
  if (j.is_object()) {
    v.kind = Value::Kind::map;
    for (const auto& [k, item] : j.items()) v.entries.emplace_back(k, from_json(item));
  } else if (j.is_array()) {
    v.kind = Value::Kind::list;
    for (const auto& item : j) v.items.push_back(from_json(item));
  } else if (!j.is_null()) {
    v.kind = Value::Kind::scalar;
    v.text = j.is_string() ? j.get<std::string>() : j.dump();
    if (j.is_number()) v.number = j.get<double>();
  }
  return v;
}

}  // namespace

Value parse_yaml(const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    io::reject(std::string("YAML parse error: ") + e.what());
  }
  return from_yaml(root);
}

Value parse_json(const std::string& text) {
  // nlohmann keeps the last of two equal keys; the callback notes any, and the file is refused.
  std::vector<std::set<std::string>> open;
  std::string twice;
  const auto note_keys = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) open.emplace_back();
    if (event == Event::object_end && !open.empty()) open.pop_back();
    if (event == Event::key && !open.empty() && twice.empty() &&
        !open.back().insert(parsed.get<std::string>()).second) {
      twice = parsed.get<std::string>();
    }
    return true;
  };
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text, note_keys);
  } catch (const nlohmann::json::exception& e) {
    io::reject(std::string("JSON parse error: ") + e.what());
  }
  if (!twice.empty()) io::reject("key '" + io::shown(twice, 100) + "' appears twice");
  return from_json(root);
}

}  // namespace groovetrace::calib
