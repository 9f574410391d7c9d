#pragma once
// The JSON of the small files Tempera reads and writes beside images (a
// guide cache's manifest.json, the rigid-body method's tracks.json): a
// value tree, a reader that names where a file is malformed, and a writer
// whose numbers read back exactly.
#include <string>
#include <utility>
#include <vector>

namespace tempera {

struct Json {
  enum class Type { Null, Bool, Number, String, Array, Object };
  Type type = Type::Null;
  bool boolean = false;
  double number = 0;
  bool integer = false;  // a number written without a fraction or an exponent
  std::string text;      // a string's
  std::vector<Json> items;                           // an array's
  std::vector<std::pair<std::string, Json>> fields;  // an object's, in file order

  // The field `key` of an object; nullptr when absent or not an object.
  const Json* find(const std::string& key) const;

  static Json of(double value);
  static Json of(std::string value);
  static Json array(std::vector<Json> items);
  static Json object(std::vector<std::pair<std::string, Json>> fields);
};

// Nesting deeper than this is refused: no real file needs it, and a
// malicious one must not exhaust the stack.
constexpr int kMaxJsonDepth = 200;

// The value of `text`, as Python's json reads it (NaN and Infinity
// included). ValueError "line L column C: what" for malformed text.
Json parse_json(const std::string& text);

// `value` as text, objects' fields sorted by key, one item per line indented
// by `indent` spaces per level; numbers in their shortest exact form.
std::string write_json(const Json& value, int indent = 1);

}  // namespace tempera
