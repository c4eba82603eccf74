// src/cli/support/progress.hpp -- what the command says on standard error besides an error: the
// progress line of a long run and the loader's warnings; --quiet silences both.
#pragma once

#include "ffsr/parsers/urdf.hpp"

#include <chrono>
#include <string>

namespace ffsr::cli {

/// --quiet: no progress line and no warning on standard error (errors are still printed). Set once,
/// when the subcommand's flags are read.
void set_quiet(bool quiet);
bool quiet();

/// One warning line on stderr per repair ("ffsr-optimize: warning: link 'x': ..."), unless quiet.
void warn_repairs(const UrdfReport& report);

/// A progress line on stderr when it is a terminal, shown once a run has lasted a second
/// (`label` names the run). Call from one thread only.
struct Progress {
  explicit Progress(std::string label_, bool quiet = false, std::string unit_ = "points");
  /// "label run  42%".
  void operator()(double fraction);
  /// "label 1234/5678 points, 1.2e+06/s, 3 s left" (`unit` instead of "points").
  void operator()(unsigned long long done, unsigned long long total);

 private:
  std::string label, unit;
  std::chrono::steady_clock::time_point start;
  bool shown = false;
  bool enabled;
};

}  // namespace ffsr::cli
