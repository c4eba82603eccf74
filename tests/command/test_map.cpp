// End-to-end tests of `ffsr-optimize map`: M_ie (Eq. 14) and closed-form F_max (Eq. 24) over a grid
// of joint angles. The values are checked against the library's integrated_effective_mass and the
// contact law, evaluated here from the angles the CSV reports; the maximum of the 3-DOF map at the
// stretched arm is the paper's Section 5.1 finding; shards put together must equal the whole map
// byte for byte; bad inputs give one error line naming the flag and leave no file behind.
#include "support/command.hpp"

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace test_map {

using namespace ffsr::test;

namespace {

CommandResult map_cli(const Args& args, const std::string& cwd) { return cli_sub("map", args, cwd); }

/// M_ie and F_max from the library for the CLI's default target and contact flags (the paper's
/// target, Herbert-McWhannell, K = 1e9, alpha = 1.5, c_r = 0.9, 0.2 m/s, spin 2 deg/s about z).
struct Reference {
  ffsr::Model model;
  ffsr::Data data;
  ffsr::Target target;
  ffsr::AnyContactLaw law;
  explicit Reference(const std::string& urdf)
      : model(ffsr::model_from_urdf_file(urdf)),
        data(model),
        target(),
        law(ffsr::make_contact_law("herbert-mcwhannell", {1e9, 1.5, 0.9}, approach_speed())) {}
  double approach_speed() {
    target.angular_velocity = Eigen::Vector3d(0, 0, 2.0 * M_PI / 180.0);
    const Eigen::Vector3d u = target.normal_world();
    return ffsr::approach_velocity(u, 0.2 * u, target.velocity, target.angular_velocity_world(),
                                   target.offset_world());
  }
  double M_ie(const Eigen::VectorXd& theta_deg) {
    const Eigen::VectorXd theta = theta_deg * (M_PI / 180.0);
    return ffsr::integrated_effective_mass(model, data, ffsr::BasePose{}, theta, model.end_effector(),
                                           target);
  }
};

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

}  // namespace

TEST_CASE("map: the 3-DOF map over the full grid at 6 deg peaks at the stretched arm and equals the library",
          "[map][cli]") {
  TempDir dir;
  const CommandResult r =
      map_cli({"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--vary", "1,2,3", "--range-deg", "-180,180",
               "--step-deg", "6", "--csv", "m.csv", "--threads", "2"},
              dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());  // stderr is a file here, not a terminal: no progress line
  const NumericCsv csv = parse_numeric_csv(read_existing_file(dir.str() + "/m.csv"));
  CHECK(csv.header == "joint1_deg,joint2_deg,joint3_deg,M_ie_kg,F_max_N");
  REQUIRE(csv.rows.size() == 60u * 60u * 60u);  // [-180, 180) in steps of 6: 60 angles per joint

  // row order: the last varied joint changes fastest; angles lo + i step
  for (size_t k = 0; k < csv.rows.size(); k += 997) {
    const auto& row = csv.rows[k];
    REQUIRE(row.size() == 5u);
    CHECK(row[0] == -180.0 + 6.0 * static_cast<double>(k / 3600));
    CHECK(row[1] == -180.0 + 6.0 * static_cast<double>((k / 60) % 60));
    CHECK(row[2] == -180.0 + 6.0 * static_cast<double>(k % 60));
  }
  // the paper's Section 5.1: M_ie is largest with the arm stretched, theta = [0, 0, 0]. Over the full
  // turn the maximum is shared by the collinear configurations (every angle 0 or -180: the arm lies
  // along the contact normal u = x, the joint columns of J_v^T u vanish, and only the base part is
  // left); the folded ones are physically impossible (the links overlap).
  double max_M = 0;
  for (const auto& row : csv.rows) max_M = std::max(max_M, row[3]);
  const size_t zero = 30 * 3600 + 30 * 60 + 30;  // index of [0, 0, 0]
  REQUIRE(csv.rows[zero][0] == 0.0);
  REQUIRE(csv.rows[zero][1] == 0.0);
  REQUIRE(csv.rows[zero][2] == 0.0);
  CHECK(rel(csv.rows[zero][3], max_M) < 1e-12);
  for (const auto& row : csv.rows)
    if (row[3] > max_M * (1 - 1e-9)) {
      INFO("a maximum at [" << row[0] << ", " << row[1] << ", " << row[2] << "]");
      CHECK(((row[0] == 0.0 || row[0] == -180.0) && (row[1] == 0.0 || row[1] == -180.0) &&
             (row[2] == 0.0 || row[2] == -180.0)));
    }

  // 100 random grid points (fixed seed) against the library, to 1e-12 relative
  Reference ref(kUrdf3);
  std::mt19937 rng(20221);
  std::uniform_int_distribution<size_t> pick(0, csv.rows.size() - 1);
  const double zeta_exponent = 1.5 / 2.5;
  for (int n = 0; n < 100; ++n) {
    const auto& row = csv.rows[pick(rng)];
    const double M = ref.M_ie(Eigen::Vector3d(row[0], row[1], row[2]));
    CHECK(rel(row[3], M) < 1e-12);
    // F_max = zeta M^(alpha/(alpha+1)) (Eq. 24)
    CHECK(rel(row[4], ffsr::zeta(ref.law) * std::pow(M, zeta_exponent)) < 1e-12);
  }
}

TEST_CASE("map: per-joint ranges and steps, the joints not varied held at --joints-deg", "[map][cli]") {
  TempDir dir;
  const CommandResult r =
      map_cli({"--urdf", kUrdf7, "--joints-deg", "10,20,30,40,50,60,70", "--vary", "2,5", "--range-deg",
               "0,10,-20,-10", "--step-deg", "5,2.5", "--csv", "m.csv", "--quiet"},
              dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const NumericCsv csv = parse_numeric_csv(read_existing_file(dir.str() + "/m.csv"));
  REQUIRE(csv.rows.size() == 2u * 4u);  // {0, 5} x {-20, -17.5, -15, -12.5}
  Reference ref(kUrdf7);
  for (size_t k = 0; k < csv.rows.size(); ++k) {
    const auto& row = csv.rows[k];
    CHECK(row[0] == 5.0 * static_cast<double>(k / 4));
    CHECK(row[1] == -20.0 + 2.5 * static_cast<double>(k % 4));
    Eigen::VectorXd q(7);
    q << 10, row[0], 30, 40, row[1], 60, 70;
    CHECK(rel(row[2], ref.M_ie(q)) < 1e-12);
  }
}

TEST_CASE("map: three shards concatenated equal the whole map byte for byte", "[map][cli]") {
  TempDir dir;
  // 52 angles per joint ([-180, 180) in steps of 7): 52^3 = 140608 points, 140608 mod 3 = 1
  const Args grid{"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--vary", "1,2,3", "--step-deg", "7"};
  Args whole = grid;
  whole.insert(whole.end(), {"--csv", "all.csv", "--threads", "1"});
  const CommandResult r = map_cli(whole, dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::string joined;
  for (int k = 0; k < 3; ++k) {
    Args part = grid;
    const std::string name = "part" + std::to_string(k) + ".csv";
    part.insert(part.end(), {"--csv", name, "--threads", "2", "--shard", std::to_string(k) + "/3"});
    const CommandResult s = map_cli(part, dir.str());
    INFO(s.err);
    REQUIRE(s.exit_code == 0);
    joined += read_existing_file(dir.str() + "/" + name);
  }
  const std::string all = read_existing_file(dir.str() + "/all.csv");
  CHECK(parse_numeric_csv(all).rows.size() == 140608u);
  CHECK(joined == all);
}

TEST_CASE("map: bad inputs give one error line naming the flag and no output file", "[map][cli][errors]") {
  const Args base{"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--csv", "m.csv"};
  const std::vector<std::pair<Args, std::string>> cases = {
      {{"--vary", "1,2", "--step-deg", "0"}, "--step-deg"},
      {{"--vary", "1,2", "--step-deg", "-2"}, "--step-deg"},
      {{"--vary", "1", "--range-deg", "10,-10"}, "--range-deg"},
      {{"--vary", "1", "--range-deg", "10,10"}, "--range-deg"},
      {{"--vary", "1,2", "--range-deg", "0,10,20"}, "--range-deg"},
      {{"--vary", "4"}, "--vary"},
      {{"--vary", "0"}, "--vary"},
      {{"--vary", "1.5"}, "--vary"},
      {{"--vary", "1,1"}, "--vary"},
      {{"--vary", "1,2,3", "--step-deg", "0.003"}, "--max-points"},  // 120000^3 points
      {{"--vary", "1,2", "--step-deg", "60", "--max-points", "35"}, "--max-points"},
      {{"--vary", "1", "--shard", "3/3"}, "--shard"},
      {{"--vary", "1", "--shard", "-1/3"}, "--shard"},
      {{"--vary", "1", "--shard", "0/0"}, "--shard"},
      {{"--vary", "1", "--shard", "1of3"}, "--shard"},
      {{"--vary", "1", "--model", "all"}, "--model"},
      {{"--vary", "1", "--model", "nope"}, "--model"},
  };
  for (const auto& [extra, flag] : cases) {
    TempDir dir;
    Args args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    const CommandResult r = map_cli(args, dir.str());
    std::string line;
    for (const auto& a : extra) line += a + " ";
    INFO(line << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.rfind("ffsr-optimize: error: ", 0) == 0);
    CHECK(r.err.find(flag) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(dir.entries().empty());
  }
  TempDir dir;
  const CommandResult r = map_cli(
      {"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--vary", "1", "--csv", "missing/m.csv"}, dir.str());
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--csv") != std::string::npos);
  CHECK(r.err.find("missing") != std::string::npos);
  CHECK(dir.entries().empty());
  // exactly at the limit is allowed: 6 x 6 = 36 points
  const CommandResult ok = map_cli({"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--vary", "1,2", "--step-deg",
                                    "60", "--max-points", "36", "--csv", "m.csv"},
                                   dir.str());
  CHECK(ok.exit_code == 0);
}

}  // namespace test_map
