// ffsr/scenario/detail/values.hpp -- the value parsers of the scenario keys (one per kind of
// value, from a TOML node and from text) and the checks of one value. Part of
// ffsr/scenario/scenario.hpp.
#pragma once

#include "ffsr/errors.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

namespace ffsr {
namespace detail {

// --- one parser per kind of value ------------------------------------------------------------------

inline std::string trimmed(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

/// A number written as text; NaN and infinities written as such pass (the validation names them), a
/// finite number too large for a double ("1e999") does not.
inline double number_from_text(const std::string& text, const std::string& key, const std::string& in = "") {
  const std::string t = trimmed(text);
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(t.c_str(), &end);
  const std::string within = in.empty() ? "" : " (in '" + in + "')";
  if (t.empty() || end != t.c_str() + t.size())
    throw InputError(str(key, ": '", t, "' is not a number", within));
  if (errno == ERANGE && std::isinf(x))
    throw InputError(str(key, ": '", t, "' is out of the range of a double", within));
  return x;
}

inline std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::string item;
  std::stringstream ss(text);
  while (std::getline(ss, item, ',')) items.push_back(item);
  return items;
}

inline std::vector<double> numbers_from_text(const std::string& text, const std::string& key) {
  if (text.empty()) throw InputError(str(key, ": expected comma-separated numbers, got an empty value"));
  if (text.back() == ',') throw InputError(str(key, ": trailing comma in '", text, "'"));
  std::vector<double> out;
  for (const std::string& item : split_list(text)) out.push_back(number_from_text(item, key, text));
  return out;
}

inline long long integer_from_text(const std::string& text, const std::string& key) {
  const std::string t = trimmed(text);
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(t.c_str(), &end, 10);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE || x < INT_MIN || x > INT_MAX)
    throw InputError(str(key, ": '", t, "' is not an integer"));
  return x;
}

/// A boolean as text (a flag's value): exactly "true" or "false", nothing else (no yes, on, 1, TRUE).
inline bool boolean_from_text(const std::string& text, const std::string& key) {
  if (text == "true") return true;
  if (text == "false") return false;
  throw InputError(str(key, ": expected true or false, got '", text, "'"));
}

/// A scalar node as text (a text key takes a number or a boolean as written).
inline std::optional<std::string> text_of(const toml::node& n) {
  if (auto s = n.value_exact<std::string>()) return *s;
  if (auto i = n.value_exact<int64_t>()) return std::to_string(*i);
  if (auto d = n.value_exact<double>()) return shortest_number(*d);
  if (auto b = n.value_exact<bool>()) return std::string(*b ? "true" : "false");
  return std::nullopt;
}

inline double number_of(const toml::node& n, const std::string& key) {
  if (auto i = n.value_exact<int64_t>()) return static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) return *d;
  if (auto s = n.value_exact<std::string>()) return number_from_text(*s, key);
  throw InputError(str(key, ": expected a number"));
}

template <class T>
T value_from_text(const std::string& text, const std::string& key) {
  if constexpr (std::is_same_v<T, std::string>) {
    return text;
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    return split_list(text);
  } else if constexpr (std::is_same_v<T, double>) {
    return number_from_text(text, key);
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    return numbers_from_text(text, key);
  } else if constexpr (std::is_same_v<T, int>) {
    return static_cast<int>(integer_from_text(text, key));
  } else {
    static_assert(std::is_same_v<T, bool>);
    return boolean_from_text(text, key);
  }
}

/// What a key of member type T takes, for messages.
template <class T>
const char* value_kind_text() {
  if constexpr (std::is_same_v<T, std::string>) return "a text value";
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return "a list of text values";
  if constexpr (std::is_same_v<T, double>) return "a number";
  if constexpr (std::is_same_v<T, std::vector<double>>) return "a list of numbers";
  if constexpr (std::is_same_v<T, int>) return "an integer";
  return "true or false";
}

template <class T>
T value_from_toml(const toml::node& n, const std::string& key) {
  if (n.is_table()) throw InputError(str(key, ": expected ", value_kind_text<T>(), ", got a table"));
  if constexpr (std::is_same_v<T, std::vector<double>> || std::is_same_v<T, std::vector<std::string>>) {
    if (const toml::array* a = n.as_array()) {
      T out;
      for (const toml::node& e : *a) {
        if constexpr (std::is_same_v<T, std::vector<double>>) {
          out.push_back(number_of(e, key));
        } else {
          const auto t = text_of(e);
          if (!t) throw InputError(str(key, ": expected a list of text values"));
          out.push_back(*t);
        }
      }
      return out;
    }
    if constexpr (std::is_same_v<T, std::vector<double>>)
      if (!n.is_string()) return {number_of(n, key)};
  } else if constexpr (std::is_same_v<T, double>) {
    return number_of(n, key);
  } else if constexpr (std::is_same_v<T, int>) {
    if (auto i = n.value_exact<int64_t>()) {
      if (*i < INT_MIN || *i > INT_MAX) throw InputError(str(key, ": '", *i, "' is not an integer"));
      return static_cast<int>(*i);
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    // a file's boolean is TOML's true or false: not 1, not "yes", not the text "true"
    if (auto b = n.value_exact<bool>()) return *b;
    const auto t = text_of(n);
    throw InputError(str(key, ": expected true or false, got ",
                         n.is_string() ? "'" + t.value_or("") + "'" : t.value_or("a list")));
  }
  const auto t = text_of(n);
  if (!t) throw InputError(str(key, ": expected a single value"));
  return value_from_text<T>(*t, key);
}

// --- checks of one value ------------------------------------------------------------------------------

inline double finite(double x, const char* key) {
  if (!std::isfinite(x)) throw InputError(str("--", key, ": must be finite, got ", x));
  return x;
}

/// The seed as a non-negative integer (text, so that a bad value names the key).
inline std::uint64_t seed_of(const std::string& sd) {
  if (sd.empty() || sd.size() > 19 || sd.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(str("--seed: expected a non-negative integer (at most 19 digits), got '", sd, "'"));
  return std::stoull(sd);
}

}  // namespace detail
}  // namespace ffsr
