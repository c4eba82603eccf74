// src/cli/figures/figure_tools.hpp -- small helpers shared by the figures' sources.
#pragma once

#include "figures/plot.hpp"

#include "ffsr/errors.hpp"

#include <iomanip>
#include <sstream>
#include <string>
#include <utility>

namespace ffsr::cli::figures::tools {

using ffsr::detail::str;
using plot::Curve;
using plot::Curve3;
using plot::Panel;
using plot::Panel3;

constexpr int kBlack = 6;

/// x with `digits` decimals.
inline std::string fixed(double x, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << x;
  return s.str();
}

/// An empty 2-D panel with its title and axis labels.
inline plot::Panel labelled(std::string title, std::string xlabel, std::string ylabel) {
  plot::Panel p;
  p.title = std::move(title);
  p.xlabel = std::move(xlabel);
  p.ylabel = std::move(ylabel);
  return p;
}

}  // namespace ffsr::cli::figures::tools
