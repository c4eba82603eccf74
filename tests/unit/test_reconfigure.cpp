// The reconfiguration before the approach (optimize/reconfigure.hpp) and the global run with it:
// the physics of both phases checked from the recorded states (finite differences, the centre of
// mass, closed forms of the quintic move), the global run on the paper's 7-DOF pose scenario, and
// the bad inputs of the reconfigure keys.
#include <catch2/catch.hpp>

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/global.hpp"
#include "ffsr/optimize/reconfigure.hpp"

#include <cmath>
#include <optional>
#include <string>

namespace test_reconfigure {

const std::string kSource = FFSR_SOURCE_DIR;
constexpr double kDeg = M_PI / 180.0;

ffsr::Scenario scenario(const std::string& rel,
                        const std::vector<std::pair<std::string, std::string>>& set = {}) {
  ffsr::ScenarioKeys k = ffsr::read_scenario_file(kSource + "/" + rel);
  for (const auto& [name, value] : set) ffsr::override_scenario_key(k, name, value);
  return ffsr::build_scenario(std::move(k));
}

std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ffsr::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

/// The system centre of mass and the total momentum of the motion given by central differences of
/// the recorded states (an independent construction: base velocity from the quaternion difference).
struct StateCheck {
  const ffsr::Model& model;
  ffsr::Data data;
  explicit StateCheck(const ffsr::Model& m) : model(m), data(m) {}
  ffsr::Vector3 com(const ffsr::CaptureSample& s) {
    ffsr::crba(model, data, s.base, s.theta);
    return data.p[0] + data.Ic[0].h / data.Ic[0].m;
  }
  /// |momentum| / (largest body momentum scale) at sample b from samples a and c (central difference).
  double momentum(const ffsr::CaptureSample& a, const ffsr::CaptureSample& b, const ffsr::CaptureSample& c) {
    const double h2 = c.t - a.t;
    Eigen::VectorXd v(model.nv());
    v.head<3>() = (c.base.position - a.base.position) / h2;
    const ffsr::Matrix3 dR =
        c.base.orientation.toRotationMatrix() * a.base.orientation.toRotationMatrix().transpose();
    const Eigen::AngleAxisd aa(dR);
    v.segment<3>(3) = aa.angle() * aa.axis() / h2;
    v.tail(model.n()) = (c.theta - a.theta) / h2;
    ffsr::crba(model, data, b.base, b.theta);
    return ffsr::momentum(model, data, v).norm();
  }
};

/// The best local optimum of `sr` whose end-effector is in the final orientation (as an angle,
/// within 1e-6 rad); empty if none.
Eigen::VectorXd oriented_optimum(const ffsr::Scenario& sc, const ffsr::CaptureSetup& setup,
                                 const ffsr::ManifoldSearchResult& sr) {
  const ffsr::Model& model = *sc.model;
  ffsr::Data d(model);
  for (const ffsr::ManifoldPoint& p : sr.local_optima) {
    ffsr::crba(model, d, sc.problem.base, p.theta);
    const ffsr::Matrix3 R = ffsr::frame_pose(model, d, sc.problem.frame).R;
    if (Eigen::AngleAxisd(setup.capture.R_end * R.transpose()).angle() < 1e-6) return p.theta;
  }
  return {};
}

/// Continuity at t_r (the reconfiguration ends at theta_pre at rest, the approach starts there) and
/// the capture at T (the capture point and the final orientation).
void check_boundary_and_capture(const ffsr::ReconfiguredRun& rr, const Eigen::VectorXd& theta_pre, double t_r,
                                const ffsr::CaptureOptions& opt) {
  const auto& s = rr.run.series;
  const size_t b = static_cast<size_t>(rr.phases[0].samples) - 1;
  CHECK(s[b].t == Approx(t_r).epsilon(1e-12));
  CHECK((s[b].theta - theta_pre).cwiseAbs().maxCoeff() < 1e-8);
  const double h = s[b + 1].t - s[b].t;
  CHECK((s[b + 1].theta - s[b].theta).cwiseAbs().maxCoeff() < opt.max_joint_rate * h);
  CHECK((s[b + 1].base.position - s[b].base.position).norm() < 1e-3 * h);
  CHECK(rr.run.tracking_error < opt.tolerance);
  CHECK(rr.run.orientation_error < opt.orientation_tolerance);
  CHECK(rr.run.steps == static_cast<long>(s.size()) - 1);
}

TEST_CASE("reconfigure: both phases conserve zero momentum, keep the centre of mass, limits and rates",
          "[reconfigure]") {
  const ffsr::Scenario sc = scenario("robots/paper_7dof_pose.toml");
  const ffsr::Model& model = *sc.model;
  ffsr::CaptureOptions opt = sc.capture;
  opt.gain = 0;
  opt.max_joint_rate = 3 * kDeg;
  opt.record_series = true;
  const ffsr::CaptureSetup setup = ffsr::prepare_capture(sc.problem, sc.task, opt);
  // a goal on the capture manifold at the initial base pose: far from the initial configuration
  ffsr::ManifoldSearchOptions so;
  so.starts = 12;
  const ffsr::ManifoldSearchResult sr =
      ffsr::search_capture_manifold(sc.problem, sc.task, setup, sc.problem.base, so);
  const Eigen::VectorXd goal = oriented_optimum(sc, setup, sr);
  REQUIRE(goal.size() == model.n());
  Eigen::VectorXd delta = goal - sc.problem.theta;  // the shorter way round for a continuous joint
  for (int k = 0; k < model.n(); ++k)
    if (!std::isfinite(model.joint(k).lower)) delta(k) = std::remainder(delta(k), 2 * M_PI);
  const double t_r = ffsr::default_reconfiguration_duration(model, sc.problem.theta, goal, opt);
  // closed form of the least time: 15/8 max_k |delta_k| / rate, and 10 % over it or T / 4
  const double least = 15.0 / 8.0 * delta.cwiseAbs().maxCoeff() / opt.max_joint_rate;
  CHECK(t_r == Approx(std::max(0.25 * opt.duration, 1.1 * least)).epsilon(1e-12));
  ffsr::ServoPolicy servo;
  servo.theta_goal = goal;
  const ffsr::ReconfiguredRun rr =
      ffsr::plan_reconfigured_capture(sc.problem, sc.task, opt, setup, goal, t_r, servo);
  const auto& s = rr.run.series;
  REQUIRE(rr.phases.size() == 2);
  REQUIRE(static_cast<long>(s.size()) == rr.phases[0].samples + rr.phases[1].samples);
  CHECK(s.back().t == Approx(opt.duration).epsilon(1e-12));

  StateCheck check(model);
  const ffsr::Vector3 com0 = check.com(s.front());
  double max_com = 0, max_p = 0, max_rate_reconf = 0, max_rate_app = 0, max_quintic = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    max_com = std::max(max_com, (check.com(s[i]) - com0).norm());
    CHECK(std::abs(s[i].base.orientation.norm() - 1) < 1e-12);
    for (int k = 0; k < model.n(); ++k) {
      CHECK(s[i].theta(k) >= model.joint(k).lower - 1e-9);
      CHECK(s[i].theta(k) <= model.joint(k).upper + 1e-9);
    }
    if (s[i].t <= t_r + 1e-9) {  // closed form of the quintic move
      double sv, sd;
      ffsr::detail::quintic(s[i].t / t_r, sv, sd);
      max_quintic =
          std::max(max_quintic, (s[i].theta - (sc.problem.theta + sv * delta)).cwiseAbs().maxCoeff());
    }
    if (i == 0 || i + 1 == s.size()) continue;
    max_p = std::max(max_p, check.momentum(s[i - 1], s[i], s[i + 1]));
    const double rate = ((s[i + 1].theta - s[i - 1].theta) / (s[i + 1].t - s[i - 1].t)).cwiseAbs().maxCoeff();
    (s[i].t < t_r ? max_rate_reconf : max_rate_app) =
        std::max(s[i].t < t_r ? max_rate_reconf : max_rate_app, rate);
  }
  // the base moves (the reaction) but the centre of mass does not
  CHECK(rr.phases[0].base_attitude_change > 1e-3);
  CHECK(max_com < 1e-9);
  CHECK(rr.run.max_com_drift < 1e-9);
  // central differences of the states: O(h^2) of the rates, against momenta of order 1 kg m/s
  INFO("momentum from differences " << max_p << ", monitored " << rr.run.max_momentum);
  CHECK(max_p < 1e-3 * rr.run.max_body_momentum + 1e-6);
  CHECK(rr.run.max_momentum < 1e-9 * (1 + rr.run.max_body_momentum));
  CHECK(rr.run.max_quaternion_error < 1e-9);
  // the quintic move by RK4 (a time-only integrand of degree 4: Simpson's error ~ h^4)
  CHECK(max_quintic < 1e-8);
  // rates: the reconfiguration's peak is 15/8 max|delta| / t_r, below the limit
  const double peak = 15.0 / 8.0 * delta.cwiseAbs().maxCoeff() / t_r;
  CHECK(rr.phases[0].max_joint_rate <= peak * (1 + 1e-12));
  CHECK(rr.phases[0].max_joint_rate > 0.99 * peak);
  CHECK(rr.phases[0].max_joint_rate <= opt.max_joint_rate);
  CHECK(max_rate_reconf <= opt.max_joint_rate * (1 + 1e-3));
  CHECK(rr.phases[1].max_joint_rate <= opt.max_joint_rate);
  CHECK(max_rate_app <= opt.max_joint_rate * (1 + 1e-3));
  check_boundary_and_capture(rr, sc.problem.theta + delta, t_r, opt);
}

// The gripper in the orientation of a configuration of very low M_ie (1.278 kg at the scenario's
// capture point, [4.3, -14.8, -31.0, 2.5, -54.7, -8.3, 32.9] deg), 134 deg away from the initial
// orientation the scenario keeps: the task alone cannot turn the gripper that far along the line (it
// loses the line at t = 103 s), so without a reconfiguration there is no plan; with one, the global
// run reaches the pose manifold's optimum in that orientation.
TEST_CASE("reconfigure: a grasp orientation the task alone cannot reach, reached with a reconfiguration",
          "[reconfigure]") {
  const std::string file = "robots/paper_7dof_pose.toml";
  const ffsr::Scenario start = scenario(file);
  const ffsr::Model& model = *start.model;
  ffsr::Data data(model);
  Eigen::VectorXd known(7);
  known << 4.3, -14.8, -31.0, 2.5, -54.7, -8.3, 32.9;
  ffsr::crba(model, data, start.problem.base, known * kDeg);
  const ffsr::Vector3 rpy = ffsr::rpy_from_rotation(ffsr::frame_pose(model, data, start.problem.frame).R) / kDeg;
  const std::string final_rpy =
      std::to_string(rpy.x()) + "," + std::to_string(rpy.y()) + "," + std::to_string(rpy.z());
  INFO("final-rpy-deg = " << final_rpy);

  ffsr::CaptureOptions opt = start.capture;
  opt.gain = 0;
  opt.max_joint_rate = 3 * kDeg;
  auto options = [&](const ffsr::Scenario& sc, ffsr::ReconfigureMode mode) {
    ffsr::GlobalCaptureOptions g;
    g.search.seed = sc.seed;
    g.search.starts = sc.keys.global_starts;
    g.reconfigure.mode = mode;
    return g;
  };
  const ffsr::Scenario sc = scenario(file, {{"final-rpy-deg", final_rpy}});
  // without a reconfiguration: the task alone's error, as before
  CHECK_THROWS_AS(ffsr::plan_capture_global(sc.problem, sc.task, opt, options(sc, ffsr::ReconfigureMode::Never)),
                  ffsr::NumericalError);

  opt.record_series = true;
  const ffsr::GlobalCaptureResult r =
      ffsr::plan_capture_global(sc.problem, sc.task, opt, options(sc, ffsr::ReconfigureMode::Auto));
  INFO("M_ie " << r.run.M_ie << " kg, manifold optimum " << r.manifold_optimum << " kg");
  CHECK(r.counters.task_alone_failure.find("cannot follow the line") != std::string::npos);
  CHECK(r.reconfigured);
  CHECK(r.run.M_ie <= 1.31);
  CHECK(std::abs(r.run.M_ie - r.manifold_optimum) <= 0.01 * r.run.M_ie);
  CHECK(r.reached_manifold_optimum);
  // the capture at T from the reached state: the orientation as an angle, the capture point
  ffsr::crba(model, data, r.run.base, r.run.theta);
  const ffsr::Pose ee = ffsr::frame_pose(model, data, sc.problem.frame);
  const ffsr::Matrix3 R_end = ffsr::rotation_from_rpy(rpy * kDeg);
  CHECK(Eigen::AngleAxisd(R_end * ee.R.transpose()).angle() < sc.capture.orientation_tolerance);
  CHECK((ee.p - r.run.capture_point).norm() < sc.capture.tolerance);
  // both phases: joint rates within the limit, joint limits, zero momentum, the centre of mass kept
  REQUIRE(r.phases.size() == 2);
  for (const ffsr::RunPhase& ph : r.phases) CHECK(ph.max_joint_rate <= 3 * kDeg * (1 + 1e-9));
  const auto& s = r.run.series;
  REQUIRE(s.size() > 2);
  StateCheck check(model);
  const ffsr::Vector3 c0 = check.com(s.front());
  double worst_momentum = 0, worst_com = 0, worst_rate = 0;
  for (size_t i = 1; i + 1 < s.size(); ++i) {
    worst_momentum = std::max(worst_momentum, check.momentum(s[i - 1], s[i], s[i + 1]));
    worst_com = std::max(worst_com, (check.com(s[i]) - c0).norm());
    worst_rate = std::max(worst_rate, (s[i + 1].theta - s[i].theta).cwiseAbs().maxCoeff() / (s[i + 1].t - s[i].t));
    CHECK(ffsr::detail::within_limits(model, s[i].theta));
  }
  INFO("momentum (central differences) " << worst_momentum << ", centre of mass " << worst_com << " m");
  CHECK(worst_momentum < 1e-3 * r.run.max_body_momentum + 1e-6);
  CHECK(worst_com < 1e-9);
  CHECK(worst_rate <= 3 * kDeg * (1 + 1e-3));
}

TEST_CASE("reconfigure: the run check learns when each checked run's approach begins", "[reconfigure]") {
  const ffsr::Scenario sc = scenario("robots/paper_3dof.toml");
  ffsr::CaptureOptions opt = sc.capture;
  opt.gain = 0;
  opt.max_joint_rate = sc.keys.max_joint_rate_deg * kDeg;
  for (const ffsr::ReconfigureMode mode : {ffsr::ReconfigureMode::Never, ffsr::ReconfigureMode::Always}) {
    ffsr::GlobalCaptureOptions g;
    g.search.seed = sc.seed;
    g.search.starts = sc.keys.global_starts;
    g.reconfigure.mode = mode;
    std::vector<double> begins;  // one per checked run
    g.check_run = [&begins](const ffsr::CaptureResult& run,
                            double approach_begin) -> std::optional<std::string> {
      CHECK(!run.series.empty());  // the check sees the recorded path
      begins.push_back(approach_begin);
      return std::nullopt;
    };
    const ffsr::GlobalCaptureResult r = ffsr::plan_capture_global(sc.problem, sc.task, opt, g);
    INFO(ffsr::reconfigure_mode_name(mode));
    REQUIRE(!begins.empty());
    CHECK(r.reconfigured == (mode == ffsr::ReconfigureMode::Always));
    // the accepted run was the last one checked: its approach begins where its first phase ends
    CHECK(begins.back() == (r.reconfigured ? r.phases.front().t_end : 0.0));
    for (double b : begins) CHECK((mode == ffsr::ReconfigureMode::Always ? b > 0 : b == 0));
  }
}

TEST_CASE("reconfigure: bad keys give one line naming the key", "[reconfigure]") {
  const std::string file = "robots/paper_7dof_pose.toml";
  CHECK(input_error_of([&] {
          scenario(file, {{"reconfigure-duration", "0"}});
        }).rfind("--reconfigure-duration: must lie in (0, duration", 0) == 0);
  CHECK(input_error_of([&] {
          scenario(file, {{"reconfigure-duration", "-3"}});
        }).rfind("--reconfigure-duration:", 0) == 0);
  CHECK(input_error_of([&] {
          scenario(file, {{"reconfigure-duration", "157"}});
        }).rfind("--reconfigure-duration: must lie in (0, duration = 157) s, got 157", 0) == 0);
  CHECK(input_error_of([&] {
          scenario(file, {{"reconfigure", "sometimes"}});
        }) == "--reconfigure: unknown reconfiguration mode 'sometimes' (auto, always or never)");
  // a reconfiguration in 10 s at 3 deg/s: a joint needs more
  const ffsr::Scenario sc = scenario(file, {{"reconfigure", "always"}, {"reconfigure-duration", "10"}});
  const ffsr::CaptureResult none;
  ffsr::CaptureResult paper = none;
  paper.theta = sc.problem.theta;
  const std::string msg = input_error_of([&] { ffsr::run_global(sc, paper, sc.objective); });
  INFO(msg);
  CHECK(msg.rfind("--reconfigure-duration: a reconfiguration in 10 s: joint '", 0) == 0);
  CHECK(msg.find("deg/s, max-joint-rate-deg is 3") != std::string::npos);
  CHECK(msg.find('\n') == std::string::npos);
}

TEST_CASE("main job: a grasp orientation only the global run reaches, the failed rows reported",
          "[reconfigure]") {
  // robots/paper_7dof_grasp.toml: the plain and paper's-method rows cannot turn the gripper to the
  // grasp orientation along the line; by default the main job stops at the first; with keep_going
  // their errors are recorded and the global run (reconfiguration first) gives the answer
  const ffsr::Scenario sc = scenario("robots/paper_7dof_grasp.toml");
  try {
    ffsr::run_scenario(sc);
    FAIL("expected the plain run to lose the line");
  } catch (const ffsr::NumericalError& e) {
    CHECK(std::string(e.what()).rfind("plain run: ", 0) == 0);
  }
  ffsr::ScenarioRunOptions keep;
  keep.keep_going = true;
  const ffsr::ScenarioResult r = ffsr::run_scenario(sc, keep);
  INFO("plain: " << r.plain_failure << "\noptimized: " << r.optimized_failure);
  CHECK(r.plain_failure.rfind("plain run: ", 0) == 0);
  CHECK(r.plain_failure.find("cannot follow the line") != std::string::npos);
  CHECK(r.optimized_failure.rfind("optimized run: ", 0) == 0);
  REQUIRE(r.global);
  const ffsr::GlobalCaptureResult& g = r.global->result;
  CHECK(g.reconfigured);
  CHECK(g.run.M_ie <= 1.31);
  CHECK(std::abs(g.run.M_ie - g.manifold_optimum) <= 0.01 * g.run.M_ie);
  CHECK(g.reached_manifold_optimum);
  CHECK(std::isnan(r.global->paper_objective));  // no paper's-method run to compare with
  CHECK(&r.first_run() == &g.run);
  // the gripper at T in the file's orientation, as an angle from forward kinematics
  const ffsr::Model& model = *sc.model;
  ffsr::Data data(model);
  ffsr::crba(model, data, g.run.base, g.run.theta);
  const ffsr::Pose ee = ffsr::frame_pose(model, data, sc.problem.frame);
  const ffsr::Matrix3 R_end = ffsr::rotation_from_rpy(ffsr::Vector3(-16.39, -6.94, -46.07) * kDeg);
  CHECK(Eigen::AngleAxisd(R_end * ee.R.transpose()).angle() < sc.capture.orientation_tolerance);
  CHECK((ee.p - g.run.capture_point).norm() < sc.capture.tolerance);

  // the JSON: each failed row's error in place of its numbers, the reductions against it null
  const nlohmann::json j = ffsr::scenario_json(sc, r, "test");
  CHECK(j.at("baseline").at("error") == r.plain_failure);
  CHECK(j.at("optimized").at("error") == r.optimized_failure);
  CHECK_FALSE(j.at("baseline").contains("integrated_effective_mass"));
  for (const char* key : {"mass_reduction_percent", "global_mass_reduction_percent",
                          "global_exact_force_reduction_percent"})
    CHECK(j.at(key).is_null());
  CHECK(j.at("global").at("integrated_effective_mass") == g.run.M_ie);
  CHECK(j.at("global").contains("base_disturbance"));
  CHECK(j.at("capture_point") == nlohmann::json(std::vector<double>(g.run.capture_point.data(),
                                                                     g.run.capture_point.data() + 3)));
}

}  // namespace test_reconfigure
