// A build without plotting: src/cli/figures/plot.cpp compiled without FFSR_WITH_PLOT (as when PLplot is
// not found) must refuse every --plot with one error naming the flag.
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

}  // namespace test_plot_stub
