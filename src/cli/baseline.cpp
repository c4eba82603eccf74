#include "baseline.hpp"

#include "ffsr/errors.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace ffsr::cli {
namespace {

using detail::str;
using nlohmann::json;

std::string show(const json& v) {
  if (v.is_array()) return str("an array of ", v.size());
  if (v.is_object()) return str("an object of ", v.size(), " keys");
  return v.dump();
}

void compare(const json& a, const json& b, const std::string& path, Tolerance tol, std::vector<std::string>& out) {
  const std::string where = path.empty() ? std::string("(top level)") : path;
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    const bool same = (x == y) || std::abs(x - y) <= tol.rtol * std::max(std::abs(x), std::abs(y)) + tol.atol;
    if (!same) out.push_back(str(where, ": stored ", a.dump(), ", now ", b.dump()));
    return;
  }
  if (a.is_object() && b.is_object()) {
    const std::string prefix = path.empty() ? "" : path + ".";
    for (const auto& [key, value] : a.items()) {
      if (!b.contains(key)) out.push_back(str(prefix, key, ": stored ", show(value), ", now missing"));
      else compare(value, b.at(key), prefix + key, tol, out);
    }
    for (const auto& [key, value] : b.items())
      if (!a.contains(key)) out.push_back(str(prefix, key, ": stored missing, now ", show(value)));
    return;
  }
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) {
      out.push_back(str(where, ": stored ", a.size(), " entries, now ", b.size()));
      return;
    }
    for (size_t i = 0; i < a.size(); ++i) compare(a[i], b[i], str(path, "[", i, "]"), tol, out);
    return;
  }
  if (a != b) out.push_back(str(where, ": stored ", show(a), ", now ", show(b)));
}

}  // namespace

json load_baseline(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(str(flag, " ", path, ": cannot open the baseline file"));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(str(flag, " ", path, ": cannot read the baseline file"));
  json j = json::parse(ss.str(), nullptr, false);
  if (j.is_discarded())
    throw InputError(str(flag, " ", path, ": not a JSON file (write a baseline with --json FILE)"));
  if (!j.is_object()) throw InputError(str(flag, " ", path, ": expected a JSON object (a result written with --json)"));
  return j;
}

std::vector<std::string> compare_results(const json& stored, const json& now, Tolerance tol,
                                         const std::vector<std::string>& skip) {
  json a = stored, b = now;
  for (const auto& key : skip) {
    if (a.is_object()) a.erase(key);
    if (b.is_object()) b.erase(key);
  }
  std::vector<std::string> out;
  compare(a, b, "", tol, out);
  return out;
}

}  // namespace ffsr::cli
