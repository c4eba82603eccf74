#include "support/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace ffsr::cli {

namespace {
bool g_quiet = false;  // --quiet of the running subcommand
}  // namespace

void set_quiet(bool quiet) { g_quiet = quiet; }
bool quiet() { return g_quiet; }

Progress::Progress(std::string label_, bool quiet, std::string unit_)
    : label(std::move(label_)),
      unit(std::move(unit_)),
      start(std::chrono::steady_clock::now()),
      enabled(!quiet && !g_quiet && isatty(fileno(stderr)) != 0) {}

void Progress::operator()(double fraction) {
  if (!enabled) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (s < 1.0 && !shown) return;
  shown = true;
  std::fprintf(stderr, "\rffsr-optimize: %s run %3.0f%%", label.c_str(), fraction * 100.0);
  if (fraction >= 1.0) std::fprintf(stderr, "\n");
}

void Progress::operator()(unsigned long long done, unsigned long long total) {
  if (!enabled) return;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (s < 1.0 && !shown) return;
  shown = true;
  const double rate = s > 0 ? static_cast<double>(done) / s : 0.0;
  const double left = rate > 0 ? static_cast<double>(total - done) / rate : 0.0;
  std::fprintf(stderr, "\rffsr-optimize: %s %llu/%llu %s (%3.0f%%), %.3g %s/s, %.0f s left   ", label.c_str(),
               done, total, unit.c_str(),
               total ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0, rate,
               unit.c_str(), left);
  if (done >= total) std::fprintf(stderr, "\n");
}

void warn_repairs(const UrdfReport& report) {
  if (g_quiet) return;
  auto list = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += (s.empty() ? "" : ", ") + detail::str(x);
    return v.size() == 1 ? s : "(" + s + ")";
  };
  for (const ModelRepair& r : report.repairs)
    std::fprintf(stderr, "ffsr-optimize: warning: link '%s': %s: %s -> %s\n", r.link.c_str(), r.what.c_str(),
                 list(r.before).c_str(), list(r.after).c_str());
}

}  // namespace ffsr::cli
