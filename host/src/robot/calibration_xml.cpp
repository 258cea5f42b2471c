// OpenCV FileStorage XML (`<opencv_storage>`) as a calib::Value tree: a strict reader of just
// the structure cv::FileStorage writes (elements, attributes, text, comments, the <?xml ?>
// declaration), not a general XML parser.

#include <cctype>
#include <string_view>

#include "io/text.hpp"
#include "robot/calibration_tree.hpp"
#include "robot/calibration_values.hpp"

namespace groovetrace::calib {
namespace {

// OpenCV's storage is a few levels deep; this bounds the recursion on hostile input.
constexpr int kMaxXmlDepth = 32;

class XmlReader {
 public:
  explicit XmlReader(const std::string& text) : s_(text) {}

  Value document() {
    skip_misc(true);
    const std::string root = peek_name();
    if (root != "opencv_storage") {
      io::reject("XML root element is '" + io::shown(root, 100) +
                 "', expected 'opencv_storage' (OpenCV FileStorage)");
    }
    Value v = element(0).second;
    skip_misc(false);
    if (pos_ != s_.size()) fail_here("text after the root element");
    if (v.kind == Value::Kind::scalar && v.text.empty()) v.kind = Value::Kind::map;
    return v;
  }

 private:
  [[noreturn]] void fail_here(const std::string& what) const {
    std::size_t line = 1;
    for (std::size_t k = 0; k < pos_ && k < s_.size(); ++k) line += s_[k] == '\n';
    io::reject("XML error at line " + std::to_string(line) + ": " + what);
  }
  bool starts(std::string_view t) const { return s_.compare(pos_, t.size(), t) == 0; }
  void skip_ws() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  void skip_past(std::string_view end, const char* what) {
    const auto at = s_.find(end, pos_);
    if (at == std::string::npos) fail_here(std::string("unterminated ") + what);
    pos_ = at + end.size();
  }
  // Whitespace, comments and (before the root only) the <?xml ...?> declaration.
  void skip_misc(bool prolog) {
    for (;;) {
      skip_ws();
      if (starts("<!--")) {
        skip_past("-->", "comment");
      } else if (prolog && starts("<?")) {
        skip_past("?>", "declaration");
      } else if (starts("<!")) {
        fail_here("DTD or CDATA is not supported");
      } else {
        return;
      }
    }
  }
  static bool name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == ':';
  }
  std::string peek_name() const {
    if (pos_ >= s_.size() || s_[pos_] != '<') return "";
    std::size_t end = pos_ + 1;
    while (end < s_.size() && name_char(s_[end])) ++end;
    return s_.substr(pos_ + 1, end - pos_ - 1);
  }
  std::string name() {
    const std::size_t begin = pos_;
    while (pos_ < s_.size() && name_char(s_[pos_])) ++pos_;
    if (pos_ == begin) fail_here("expected an element name");
    return s_.substr(begin, pos_ - begin);
  }
  // Attributes are read and checked, not kept: OpenCV's type_id is implied by the content.
  void attributes() {
    for (;;) {
      skip_ws();
      if (pos_ >= s_.size()) fail_here("unterminated tag");
      if (s_[pos_] == '>' || s_[pos_] == '/') return;
      name();
      skip_ws();
      if (!starts("=")) fail_here("expected '=' after an attribute name");
      ++pos_;
      skip_ws();
      if (pos_ >= s_.size() || (s_[pos_] != '"' && s_[pos_] != '\'')) {
        fail_here("expected a quoted attribute value");
      }
      const char quote = s_[pos_++];
      const auto end = s_.find(quote, pos_);
      if (end == std::string::npos) fail_here("unterminated attribute value");
      pos_ = end + 1;
    }
  }
  void entity(std::string& text) {
    static const std::pair<const char*, char> kEntities[] = {
        {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
    for (const auto& [name, c] : kEntities) {
      if (starts(name)) {
        text += c;
        pos_ += std::string_view(name).size();
        return;
      }
    }
    fail_here("unknown entity");
  }
  // <name attr="...">content</name> or <name/>: the name and its value.
  std::pair<std::string, Value> element(int depth) {
    if (depth > kMaxXmlDepth) fail_here("elements nested too deep");
    ++pos_;  // '<'
    std::string tag = name();
    attributes();
    Value v;
    v.kind = Value::Kind::scalar;
    if (starts("/>")) {
      pos_ += 2;
      return {tag, v};
    }
    ++pos_;  // '>'
    std::string text;
    std::vector<std::pair<std::string, Value>> children;
    for (;;) {
      if (pos_ >= s_.size()) fail_here("element '" + io::shown(tag, 100) + "' is not closed");
      if (starts("</")) break;
      if (starts("<!--")) {
        skip_past("-->", "comment");
      } else if (starts("<!") || starts("<?")) {
        fail_here("CDATA or processing instructions are not supported");
      } else if (s_[pos_] == '<') {
        children.push_back(element(depth + 1));
      } else if (s_[pos_] == '&') {
        entity(text);
      } else {
        text += s_[pos_++];
      }
    }
    pos_ += 2;
    if (name() != tag) fail_here("closing tag does not match '" + io::shown(tag, 100) + "'");
    skip_ws();
    if (!starts(">")) fail_here("expected '>'");
    ++pos_;
    return {tag, children.empty() ? scalar(text) : container(tag, text, std::move(children))};
  }
  Value scalar(const std::string& raw) const {
    Value v;
    v.kind = Value::Kind::scalar;
    const auto b = raw.find_first_not_of(" \t\r\n");
    v.text = b == std::string::npos ? "" : raw.substr(b, raw.find_last_not_of(" \t\r\n") - b + 1);
    double d = 0;
    if (!v.text.empty() && parse_decimal(v.text, d)) v.number = d;
    return v;
  }
  Value container(const std::string& tag, const std::string& text,
                  std::vector<std::pair<std::string, Value>> children) const {
    if (text.find_first_not_of(" \t\r\n") != std::string::npos) {
      io::reject("XML element '" + io::shown(tag, 100) + "' mixes text and elements");
    }
    Value v;
    bool all_items = true;
    for (const auto& child : children) all_items = all_items && child.first == "_";
    if (all_items) {
      v.kind = Value::Kind::list;
      for (auto& child : children) v.items.push_back(std::move(child.second));
      return v;
    }
    v.kind = Value::Kind::map;
    for (auto& [key, child] : children) {
      if (v.find(key)) io::reject("XML element '" + io::shown(key, 100) + "' appears twice");
      v.entries.emplace_back(key, std::move(child));
    }
    return v;
  }

  const std::string& s_;
  std::size_t pos_ = 0;
};

}  // namespace

Value parse_opencv_xml(const std::string& text) { return XmlReader(text).document(); }

}  // namespace groovetrace::calib
