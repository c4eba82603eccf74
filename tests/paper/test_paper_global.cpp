// The paper's scenarios through the global capture search (optimize/global.hpp): the bounds on M_ie
// and F_max it must reach on robots/paper_3dof.toml and robots/paper_7dof_position.toml, never worse
// than the paper's method, and the command's global row on robots/paper_7dof_pose.toml.
#include <catch2/catch.hpp>

#include "support/command.hpp"
#include "support/global_capture.hpp"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

namespace test_paper_global {

using namespace ffsr::test;
using namespace ffsr::test::global_capture;

TEST_CASE("Global capture, 3-DOF (robots/paper_3dof.toml)", "[global][paper]") {
  check_run(shared_3dof(), 1.26);  // bound: <= 1.26 kg (paper's method 1.22 in the paper, 1.31 here)
}

TEST_CASE("Global capture, 7-DOF position (robots/paper_7dof_position.toml)", "[global][paper]") {
  const Shared& s = shared_7dof_position();
  check_run(s, 1.35);                              // bound: <= 1.35 kg (paper 2.70 kg)
  CHECK(s.global.run.f_max_closed_form <= 800.0);  // bound: <= 0.80 kN (paper 1.17 kN)
}

TEST_CASE("ffsr-optimize: the global row and its JSON keys (7-DOF pose scenario)", "[global][cli][paper]") {
#if defined(FFSR_SANITIZED) && !defined(__OPTIMIZE__)
  // the full 7-DOF pose run with its global search takes many minutes at -O0 with ASan: skipped there
  // (.ci/run builds its sanitizer stage with -O1, where it runs); the library cases above run the global
  // search under the sanitizers at any optimization level
  WARN("skipped in an unoptimized sanitizer build (runs at -O1 and in Release)");
  return;
#endif
  TempDir tmp;
  const std::string out = tmp.str() + "/r.json";
  const auto r = cli({"--quiet", "--config", kRobots + "paper_7dof_pose.toml", "--json", out});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("Global") != std::string::npos);
  CHECK(r.out.find("Reduction (global)") != std::string::npos);
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto& g = j["global"];
  for (const char* key :
       {"capture_configuration_deg", "integrated_effective_mass", "f_max_closed_form", "f_max_exact",
        "tracking_error", "max_total_momentum", "max_center_of_mass_drift", "manifold_optimum",
        "optimality_gap_percent", "shooting_iterations", "max_joint_rate_deg", "search"})
    CHECK(g.contains(key));
  for (const char* key : {"method", "starts", "evaluations", "seconds"}) CHECK(g["search"].contains(key));
  CHECK(j["baseline"].contains("max_joint_rate_deg"));
  CHECK(j["optimized"].contains("max_joint_rate_deg"));
  // the pose task (one null-space direction) at most 15.70 kg, never worse than the paper's method
  const double M = g["integrated_effective_mass"].get<double>();
  std::printf("\n7-DOF pose: global M_ie %.3f kg (paper's method %.3f kg), gap %.3f %%, rate %.3f deg/s\n", M,
              j["optimized"]["integrated_effective_mass"].get<double>(),
              g["optimality_gap_percent"].get<double>(), g["max_joint_rate_deg"].get<double>());
  CHECK(M <= 15.70);
  CHECK(M <= j["optimized"]["integrated_effective_mass"].get<double>());
  CHECK(g["tracking_error"].get<double>() <= 1e-3);
  CHECK(g["orientation_error_deg"].get<double>() <= 0.5);
  CHECK(g["max_joint_rate_deg"].get<double>() <= 3.0 + 1e-9);
  // on the 1-D self-motion manifold of the pose task the optimum may lie on a component the arm cannot
  // reach; the result says so, and the gap is then the honest distance to it
  if (g["reached_manifold_optimum"].get<bool>()) CHECK(g["optimality_gap_percent"].get<double>() <= 1.0);
  CHECK(g["optimality_gap_percent"].get<double>() >= -1e-6);
}

}  // namespace test_paper_global
