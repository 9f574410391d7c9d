#include "tempera/app/json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "tempera/engine/error.hpp"

namespace tempera {
namespace {

class Reader {
 public:
  explicit Reader(const std::string& text) : s_(text) {}

  Json document() {
    Json v = value(0);
    skip_space();
    if (at_ < s_.size()) fail("extra data after the value");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    int line = 1, column = 1;
    for (std::size_t i = 0; i < at_ && i < s_.size(); ++i) s_[i] == '\n' ? (++line, column = 1) : ++column;
    throw ValueError(concat("line ", line, " column ", column, ": ", what));
  }

  void skip_space() {
    while (at_ < s_.size() && (s_[at_] == ' ' || s_[at_] == '\t' || s_[at_] == '\n' || s_[at_] == '\r')) ++at_;
  }

  bool take(const char* word) {
    const std::size_t n = std::char_traits<char>::length(word);
    if (s_.compare(at_, n, word) != 0) return false;
    at_ += n;
    return true;
  }

  void expect(char c) {
    skip_space();
    if (at_ >= s_.size() || s_[at_] != c) fail(concat("expected '", c, "'"));
    ++at_;
  }

  Json value(int depth) {
    if (depth > kMaxJsonDepth) fail("nested too deeply");
    skip_space();
    if (at_ >= s_.size()) fail("expected a value");
    Json v;
    const char c = s_[at_];
    if (c == '{') return object(depth);
    if (c == '[') return array(depth);
    if (c == '"') return Json::of(string());
    if (take("true") || take("false")) {
      v.type = Json::Type::Bool;
      v.boolean = s_[at_ - 1] == 'e' && s_[at_ - 4] == 't';
      return v;
    }
    if (take("null")) return v;
    if (take("NaN")) return Json::of(std::numeric_limits<double>::quiet_NaN());
    if (take("Infinity")) return Json::of(std::numeric_limits<double>::infinity());
    if (take("-Infinity")) return Json::of(-std::numeric_limits<double>::infinity());
    return number();
  }

  Json object(int depth) {
    Json v;
    v.type = Json::Type::Object;
    ++at_;
    skip_space();
    if (at_ < s_.size() && s_[at_] == '}') return ++at_, v;
    for (;;) {
      skip_space();
      if (at_ >= s_.size() || s_[at_] != '"') fail("expected a field name in double quotes");
      std::string key = string();
      expect(':');
      Json item = value(depth + 1);
      const auto same = std::find_if(v.fields.begin(), v.fields.end(), [&](const auto& f) { return f.first == key; });
      if (same != v.fields.end()) same->second = std::move(item);  // the last one wins, as in Python
      else v.fields.emplace_back(std::move(key), std::move(item));
      skip_space();
      if (at_ < s_.size() && s_[at_] == ',') { ++at_; continue; }
      expect('}');
      return v;
    }
  }

  Json array(int depth) {
    Json v;
    v.type = Json::Type::Array;
    ++at_;
    skip_space();
    if (at_ < s_.size() && s_[at_] == ']') return ++at_, v;
    for (;;) {
      v.items.push_back(value(depth + 1));
      skip_space();
      if (at_ < s_.size() && s_[at_] == ',') { ++at_; continue; }
      expect(']');
      return v;
    }
  }

  unsigned hex4() {
    if (at_ + 4 > s_.size()) fail("a \\u escape needs 4 hex digits");
    unsigned code = 0;
    const auto [end, ec] = std::from_chars(s_.data() + at_, s_.data() + at_ + 4, code, 16);
    if (ec != std::errc() || end != s_.data() + at_ + 4) fail("a \\u escape needs 4 hex digits");
    at_ += 4;
    return code;
  }

  static void put_utf8(std::string& out, unsigned code) {
    if (code < 0x80) {
      out += char(code);
    } else if (code < 0x800) {
      out += char(0xC0 | (code >> 6)), out += char(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      out += char(0xE0 | (code >> 12)), out += char(0x80 | ((code >> 6) & 0x3F)), out += char(0x80 | (code & 0x3F));
    } else {
      out += char(0xF0 | (code >> 18)), out += char(0x80 | ((code >> 12) & 0x3F));
      out += char(0x80 | ((code >> 6) & 0x3F)), out += char(0x80 | (code & 0x3F));
    }
  }

  std::string string() {
    ++at_;  // the opening quote
    std::string out;
    for (;;) {
      if (at_ >= s_.size()) fail("unterminated string");
      const char c = s_[at_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("a control character in a string");
      if (c != '\\') { out += c; continue; }
      if (at_ >= s_.size()) fail("unterminated string");
      const char e = s_[at_++];
      switch (e) {
        case '"': case '\\': case '/': out += e; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          unsigned code = hex4();
          if (code >= 0xD800 && code < 0xDC00 && s_.compare(at_, 2, "\\u") == 0) {  // a surrogate pair
            at_ += 2;
            const unsigned low = hex4();
            if (low >= 0xDC00 && low < 0xE000) code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
            else put_utf8(out, code), code = low;
          }
          put_utf8(out, code);
          break;
        }
        default: fail(concat("an unknown escape '\\", e, "'"));
      }
    }
  }

  Json number() {
    const std::size_t start = at_;
    if (at_ < s_.size() && s_[at_] == '-') ++at_;
    const std::size_t digits = at_;
    while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) ++at_;
    if (at_ == digits) fail("expected a value");
    if (s_[digits] == '0' && at_ - digits > 1) fail("a number with a leading zero");
    bool integer = true;
    if (at_ < s_.size() && s_[at_] == '.') {
      integer = false;
      const std::size_t fraction = ++at_;
      while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) ++at_;
      if (at_ == fraction) fail("expected digits after '.'");
    }
    if (at_ < s_.size() && (s_[at_] == 'e' || s_[at_] == 'E')) {
      integer = false;
      ++at_;
      if (at_ < s_.size() && (s_[at_] == '+' || s_[at_] == '-')) ++at_;
      const std::size_t exponent = at_;
      while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) ++at_;
      if (at_ == exponent) fail("expected digits in the exponent");
    }
    Json v = Json::of(std::strtod(s_.substr(start, at_ - start).c_str(), nullptr));
    v.integer = integer;
    return v;
  }

  const std::string& s_;
  std::size_t at_ = 0;
};

void put_string(std::string& out, const std::string& s) {
  out += '"';
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04x", unsigned(c));
      out += code;
    } else out += c;
  }
  out += '"';
}

void put_number(std::string& out, const Json& v) {
  if (std::isnan(v.number)) { out += "NaN"; return; }
  if (std::isinf(v.number)) { out += v.number > 0 ? "Infinity" : "-Infinity"; return; }
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v.number).ptr;
  out.append(text, end);
}

void put(std::string& out, const Json& v, int indent, int level) {
  const std::string pad = "\n" + std::string(std::size_t(indent * (level + 1)), ' ');
  const std::string close = "\n" + std::string(std::size_t(indent * level), ' ');
  switch (v.type) {
    case Json::Type::Null: out += "null"; return;
    case Json::Type::Bool: out += v.boolean ? "true" : "false"; return;
    case Json::Type::Number: put_number(out, v); return;
    case Json::Type::String: put_string(out, v.text); return;
    case Json::Type::Array:
      if (v.items.empty()) { out += "[]"; return; }
      out += '[';
      for (std::size_t i = 0; i < v.items.size(); ++i) out += (i ? "," : "") + pad, put(out, v.items[i], indent, level + 1);
      out += close + "]";
      return;
    case Json::Type::Object: {
      if (v.fields.empty()) { out += "{}"; return; }
      std::vector<const std::pair<std::string, Json>*> sorted;
      for (const auto& f : v.fields) sorted.push_back(&f);
      std::sort(sorted.begin(), sorted.end(), [](const auto* a, const auto* b) { return a->first < b->first; });
      out += '{';
      for (std::size_t i = 0; i < sorted.size(); ++i) {
        out += (i ? "," : "") + pad;
        put_string(out, sorted[i]->first);
        out += ": ";
        put(out, sorted[i]->second, indent, level + 1);
      }
      out += close + "}";
      return;
    }
  }
}

}  // namespace

const Json* Json::find(const std::string& key) const {
  for (const auto& [name, value] : fields)
    if (name == key) return &value;
  return nullptr;
}

Json Json::of(double value) {
  Json v;
  v.type = Type::Number;
  v.number = value;
  v.integer = std::nearbyint(value) == value && std::abs(value) < 1e15;
  return v;
}

Json Json::of(std::string value) {
  Json v;
  v.type = Type::String;
  v.text = std::move(value);
  return v;
}

Json Json::array(std::vector<Json> items) {
  Json v;
  v.type = Type::Array;
  v.items = std::move(items);
  return v;
}

Json Json::object(std::vector<std::pair<std::string, Json>> fields) {
  Json v;
  v.type = Type::Object;
  v.fields = std::move(fields);
  return v;
}

Json parse_json(const std::string& text) { return Reader(text).document(); }

std::string write_json(const Json& value, int indent) {
  std::string out;
  put(out, value, indent, 0);
  return out;
}

}  // namespace tempera
