// A build without plotting: src/cli/figures/plot.cpp compiled without FFSR_WITH_PLOT (as when PLplot is
// not found) must refuse every --plot with one error naming the flag.
#include "cli/figures/figures.hpp"
#include "cli/figures/plot.hpp"

#include "ffsr/errors.hpp"

#include <catch2/catch.hpp>

namespace test_plot_stub {

TEST_CASE("plot stub: --plot in a build without plotting is a one-line InputError", "[plot]") {
  using namespace ffsr::cli;
  CHECK_FALSE(plot::available());
  const std::string expected = "--plot: this ffsr-optimize was built without plotting";
  CHECK_THROWS_AS(plot::require_available("--plot"), ffsr::InputError);
  CHECK_THROWS_WITH(plot::require_available("--plot"), Catch::StartsWith(expected));
  plot::Figure f;
  f.name = "x";
  CHECK_THROWS_WITH(plot::render({f}, "/tmp", plot::Format::Png), Catch::StartsWith(expected));
  try {
    plot::require_available("--plot");
  } catch (const ffsr::InputError& e) {
    CHECK(std::string(e.what()).find('\n') == std::string::npos);
  }
  // the format is still checked (the error for a bad format comes first, as in the real build)
  CHECK_THROWS_WITH(plot::parse_format("tiff", "--plot-format"),
                    Catch::StartsWith("--plot-format: unknown format"));
}

TEST_CASE("plot stub: the detumble figure is described, and drawing it is refused with the one line",
          "[plot][detumble]") {
  using namespace ffsr::cli;
  figures::DetumbleSeries s;
  s.joint_names = {"a"};
  s.torque_limit = {1};
  figures::DetumbleSeries::Run r;
  r.label = "plain";
  r.t = {0, 1};
  r.joint_rate = r.relative_rate = r.stack_rate = r.force = r.moment = r.attitude = r.energy = {1, 0};
  r.rate = r.torque = {Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1)};
  r.wheel = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  s.runs = {r};
  const plot::Figure f = figures::detumble(s);
  CHECK(f.panels.size() == 6);
  CHECK_THROWS_WITH(plot::render({f}, "/tmp", plot::Format::Png),
                    Catch::StartsWith("--plot: this ffsr-optimize was built without plotting"));
}

}  // namespace test_plot_stub
