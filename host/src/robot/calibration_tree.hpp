#pragma once
// The parsed text of a calibration file as one small tree, whatever its syntax (YAML, JSON or
// OpenCV's XML), so that each layout (docs/frames.md) is interpreted once. Every reader throws
// io::Rejected (the reason, without the path) for text it cannot use.

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace::calib {

/// One node: null, a scalar (text, and its number when it reads as one), a list or a map.
struct Value {
  enum class Kind { null, scalar, list, map };
  Kind kind = Kind::null;
  std::string text;              ///< a scalar's text (a JSON string without its quotes)
  std::optional<double> number;  ///< a scalar that is a number (a JSON string is none)
  std::vector<Value> items;      ///< a list's elements
  std::vector<std::pair<std::string, Value>> entries;  ///< a map's, in file order, keys unique

  bool is_map() const { return kind == Kind::map; }
  bool is_list() const { return kind == Kind::list; }
  /// The map entry called `key`, or nullptr (also when this is no map).
  const Value* find(const std::string& key) const;
};

/// YAML (yaml-cpp): a key given twice is refused, not one of them silently kept.
Value parse_yaml(const std::string& text);
/// JSON (nlohmann): a key given twice is refused.
Value parse_json(const std::string& text);
/// OpenCV FileStorage XML: `<opencv_storage>` holding elements; an element with children is a
/// map (a list when they are all `_`), one with text is a scalar. A strict reader of just
/// that: no DTD, CDATA or mixed content.
Value parse_opencv_xml(const std::string& text);

}  // namespace groovetrace::calib
