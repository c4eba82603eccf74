#include "support/parse.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace ffsr::cli {

using detail::str;

std::vector<double> parse_list(const std::string& text, const std::string& flag, std::vector<size_t> counts) {
  std::vector<double> out;
  std::string item;
  std::stringstream ss(text);
  if (text.empty()) throw InputError(str(flag, ": expected comma-separated numbers, got an empty value"));
  while (std::getline(ss, item, ',')) {
    const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    const std::string t = b == std::string::npos ? std::string() : item.substr(b, e - b + 1);
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size())
      throw InputError(str(flag, ": '", t, "' is not a number (in '", text, "')"));
    if (!std::isfinite(x) || errno == ERANGE)
      throw InputError(str(flag, ": '", t, "' is not a finite number (in '", text, "')"));
    out.push_back(x);
  }
  if (!text.empty() && text.back() == ',') throw InputError(str(flag, ": trailing comma in '", text, "'"));
  if (!counts.empty()) {
    bool ok = false;
    std::string expected;
    for (size_t c : counts) {
      ok = ok || out.size() == c;
      expected += (expected.empty() ? "" : " or ") + std::to_string(c);
    }
    if (!ok)
      throw InputError(str(flag, ": expected ", expected, " comma-separated numbers, got ", out.size(), " ('",
                           text, "')"));
  }
  return out;
}

Vector3 parse_vec3(const std::string& text, const std::string& flag) {
  const auto v = parse_list(text, flag, {3});
  return {v[0], v[1], v[2]};
}

std::uint64_t parse_count(const std::string& text, const std::string& flag) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(str(flag, ": expected a non-negative integer, got '", text, "'"));
  return std::stoull(text);
}

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw InputError(str("--shard: expected K/N, got '", text, "'"));
  Shard s;
  s.k = parse_count(text.substr(0, slash), "--shard");
  s.n = parse_count(text.substr(slash + 1), "--shard");
  if (s.n < 1) throw InputError("--shard: N must be at least 1");
  if (s.k >= s.n) throw InputError(str("--shard: K must be less than N (K counts from 0), got ", text));
  return s;
}

double deg2rad(double deg) { return deg * M_PI / 180.0; }
double rad2deg(double rad) { return rad * 180.0 / M_PI; }

}  // namespace ffsr::cli
