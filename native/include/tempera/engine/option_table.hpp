#pragma once
// Typed option tables. An options struct declares its fields with their
// defaults; its table lists, once, each field's name, command-line flag, help
// text and valid range. Everything else is derived from the table: range
// validation, the CLI flags and their --help, the Python classes and keyword
// checks (native/python/bind_options.hpp), the Blender property defaults (from
// the table exported to Python) and the canonical settings text of resume keys.
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include "tempera/engine/error.hpp"

namespace tempera {

// Names of an enum's values, in declaration order, and what the enum is
// called in messages; specialised next to each enum used as an option:
// `static constexpr const char* what` and `std::array<const char*, N> names`.
template <class E>
struct EnumNames;

template <class E, class = void>
struct is_named_enum : std::false_type {};
template <class E>
struct is_named_enum<E, std::void_t<decltype(EnumNames<E>::names)>> : std::true_type {};

template <class E>
const char* enum_name(E value) {
  return EnumNames<E>::names[std::size_t(value)];
}

template <class E>
std::string enum_choices() {
  std::string out;
  for (const char* n : EnumNames<E>::names) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

template <class E>
E parse_enum(std::string_view text, std::string_view what) {
  const auto& names = EnumNames<E>::names;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (text == names[i]) return E(i);
  throw ValueError(concat("unknown ", what, " '", text, "' (choose ", enum_choices<E>(), ")"));
}

// One field of an options struct.
template <class S, class T>
struct Field {
  T S::*member;
  const char* name;  // Python keyword / attribute, also the settings-text key
  const char* flag;  // command-line flag without the leading dashes ("" = not on the CLI)
  const char* help;  // what it does to the picture, with typical values
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool in_settings = true;  // part of settings_text (false: does not change results, e.g. threads)
};

// The same field, left out of settings_text.
template <class S, class T>
constexpr Field<S, T> not_in_settings(Field<S, T> f) {
  f.in_settings = false;
  return f;
}

template <class S, class T>
constexpr Field<S, T> field(T S::*member, const char* name, const char* flag, const char* help,
                            double min = -std::numeric_limits<double>::infinity(),
                            double max = std::numeric_limits<double>::infinity()) {
  return Field<S, T>{member, name, flag, help, min, max, true};
}

template <class Tuple, class F>
void for_each_field(const Tuple& table, F&& f) {
  std::apply([&](const auto&... fld) { (f(fld), ...); }, table);
}

// ---- values as text (CLI, settings text) ----

template <class T>
std::string format_value(const T& v) {
  if constexpr (std::is_same_v<T, bool>) {
    return v ? "true" : "false";
  } else if constexpr (std::is_enum_v<T>) {
    return enum_name(v);
  } else if constexpr (std::is_arithmetic_v<T>) {
    std::ostringstream s;
    s.precision(std::is_same_v<T, float> ? 7 : 12);  // "2.2", not the float's 2.20000005
    s << v;
    return s.str();
  } else {  // std::vector of numbers
    std::string out;
    for (const auto& x : v) out += (out.empty() ? "" : ",") + format_value(x);
    return out;
  }
}

template <class T>
T parse_number(std::string_view text, std::string_view what) {
  T out{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    throw ValueError(concat(what, " expects a number, got '", text, "'"));
  return out;
}

template <class T>
T parse_value(std::string_view text, std::string_view what) {
  if constexpr (std::is_same_v<T, bool>) {
    if (text == "true" || text == "1" || text == "on") return true;
    if (text == "false" || text == "0" || text == "off") return false;
    throw ValueError(concat(what, " expects true or false, got '", text, "'"));
  } else if constexpr (std::is_enum_v<T>) {
    return parse_enum<T>(text, EnumNames<T>::what);
  } else if constexpr (std::is_arithmetic_v<T>) {
    return parse_number<T>(text, what);
  } else {
    T out;
    std::size_t start = 0;
    while (start <= text.size() && !text.empty()) {
      const std::size_t end = std::min(text.find(',', start), text.size());
      out.push_back(parse_number<typename T::value_type>(text.substr(start, end - start), what));
      start = end + 1;
    }
    return out;
  }
}

// ---- validation ----

// "guide_variance" -> "guide variance", as messages name options.
inline std::string spoken(const char* name) {
  std::string out = name;
  for (auto& c : out)
    if (c == '_') c = ' ';
  return out;
}

template <class T>
void check_range(const T& v, const char* name, double min, double max) {
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
    const double x = double(v);
    if (!std::isfinite(x) || x < min || x > max)
      throw ValueError(concat(spoken(name), " must be in [", format_value(min), ", ", format_value(max), "], got ",
                              format_value(v)));
  } else if constexpr (!std::is_arithmetic_v<T> && !std::is_enum_v<T>) {
    for (const auto& x : v) check_range(x, name, min, max);
  }
}

// Range check of every field of `options` against its table.
template <class S, class Tuple>
void validate_fields(const S& options, const Tuple& table) {
  for_each_field(table, [&](const auto& f) { check_range(options.*f.member, f.name, f.min, f.max); });
}

// "name=value;name=value;..." over the fields of the table, for resume keys.
template <class S, class Tuple>
std::string settings_text(const S& options, const Tuple& table) {
  std::string out;
  for_each_field(table, [&](const auto& f) {
    if (f.in_settings) out += std::string(f.name) + "=" + format_value(options.*f.member) + ";";
  });
  return out;
}

// Sets the field whose flag is `flag` (without dashes) from the text that
// `value()` returns (called only then, so it may consume an argument); false
// if the table has no such flag.
template <class S, class Tuple, class Value>
bool set_from_flag(S& options, const Tuple& table, std::string_view flag, Value&& value) {
  bool found = false;
  for_each_field(table, [&](const auto& f) {
    using T = std::decay_t<decltype(options.*f.member)>;
    if (found || flag != f.flag || *f.flag == 0) return;
    options.*f.member = parse_value<T>(value(), concat("--", f.flag));
    found = true;
  });
  return found;
}

// set_from_flag for an option given as text, as a registered method's
// options arrive (methods/registry.hpp, MethodOptions): an empty text is a
// bare switch, true for a yes/no field and "--flag needs a value" for any
// other. False if the table has no such flag.
template <class S, class Tuple>
bool set_from_text(S& options, const Tuple& table, std::string_view flag, const std::string& text) {
  return set_from_flag(options, table, flag, [&] {
    bool yes_no = false;
    for_each_field(table, [&](const auto& f) {
      if (*f.flag != 0 && flag == f.flag) yes_no = std::is_same_v<std::decay_t<decltype(options.*f.member)>, bool>;
    });
    if (!text.empty() || !yes_no) {
      if (text.empty()) throw ValueError(concat("--", flag, " needs a value"));
      return text;
    }
    return std::string("true");
  });
}

// "  --flag VALUE   help (default D)" lines for --help. With `bare_switches`
// a yes/no field reads "--flag [V]": given alone, it means true (set_from_text).
template <class S, class Tuple>
std::string flags_help(const Tuple& table, bool bare_switches = false) {
  const S defaults{};
  std::string out;
  for_each_field(table, [&](const auto& f) {
    if (*f.flag == 0) return;
    using T = std::decay_t<decltype(defaults.*f.member)>;
    const char* value = std::is_enum_v<T> ? "MODE" : bare_switches && std::is_same_v<T, bool> ? "[V]" : "V";
    std::string left = std::string("  --") + f.flag + " " + value;
    left.resize(std::max<std::size_t>(left.size() + 1, 26), ' ');
    std::string choices;
    if constexpr (std::is_enum_v<T>) choices = " [" + enum_choices<T>() + "]";
    const std::string def = format_value(defaults.*f.member);
    out += left + f.help + choices + " (default " + (def.empty() ? "none" : def) + ")\n";
  });
  return out;
}

}  // namespace tempera
