// The front of (M_ie, base angular rate jump) on the capture manifold (optimize/pareto.hpp).
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include <string>

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/pareto.hpp"

namespace test_pareto {

using namespace ffsr;
using ffsr::test::kRobots;

/// The 7-DOF position task of the paper (T = 157 s) at its initial base pose.
struct Paper7Position {
  Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb = problem();
  CaptureTask task;  // position
  CaptureSetup s = setup();
  BasePose base;  // the initial base pose

  /// The front from 8 starts at `levels` base-rate levels.
  ParetoFront front(int levels) const {
    ParetoOptions o;
    o.starts = 8;
    o.levels = levels;
    return pareto_front(pb, task, s, base, o);
  }

 private:
  CaptureProblem problem() const {
    CaptureProblem p = ffsr::test::problem_7dof(m);
    p.contact = ffsr::test::kPaperContact;
    return p;
  }
  CaptureSetup setup() const {
    CaptureOptions opt;
    opt.duration = 157;
    return prepare_capture(pb, task, opt);
  }
};

TEST_CASE_METHOD(Paper7Position,
                 "Pareto front of M_ie and the base rate jump: non-dominated, on the manifold, ends optimal",
                 "[pareto]") {
  const ParetoFront f = front(24);
  INFO("points " << f.points.size() << " ends " << f.min_mass.M_ie << " kg / " << f.min_mass.base_rate
                 << " rad/s and " << f.min_rate.M_ie << " kg / " << f.min_rate.base_rate << " rad/s, hv "
                 << f.hypervolume_normalized);
  CHECK(f.points.size() >= 20);
  Data d(m);
  Eigen::VectorXd r;
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, s.capture.v_in);
  for (size_t i = 0; i < f.points.size(); ++i) {
    const ParetoPoint& p = f.points[i];
    if (i > 0) {  // M_ie increasing, rate decreasing: no point dominates another
      CHECK(p.M_ie > f.points[i - 1].M_ie);
      CHECK(p.base_rate < f.points[i - 1].base_rate);
    }
    capture_residual(m, d, pb, task, s, base, p.theta, r, nullptr);
    CHECK(r.norm() < 1e-9);
    // the rate again, through the whole-configuration function (target at T, the law at delta_dot^-)
    const BaseDisturbance bd = base_disturbance(m, d, base, p.theta, pb.frame, s.capture.target, law);
    CHECK(bd.angular_rate() == Approx(p.base_rate).epsilon(1e-12));
    CHECK(bd.M_ie == Approx(p.M_ie).epsilon(1e-12));
  }
  // the ends are the front's first and last points and the single-objective optima
  CHECK(f.points.front().M_ie == f.min_mass.M_ie);
  CHECK(f.points.back().base_rate == f.min_rate.base_rate);
  ManifoldSearchOptions so;
  so.starts = 8;
  CHECK(search_capture_manifold(pb, task, s, base, so).best.M_ie >= f.min_mass.M_ie * (1 - 1e-9));
  CHECK(f.knee > 0);
  CHECK(f.knee + 1 < f.points.size());
  CHECK(f.hypervolume_normalized > 0.0);
  CHECK(f.hypervolume_normalized < 1.0);
  CHECK(f.evaluations > 0);
}

TEST_CASE("Pareto front: bad options", "[pareto]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb = ffsr::test::problem_7dof(m);
  CaptureOptions opt;
  opt.duration = 157;
  const CaptureSetup s = prepare_capture(pb, CaptureTask{}, opt);
  ParetoOptions o;
  o.levels = 0;
  CHECK_THROWS_AS(pareto_front(pb, CaptureTask{}, s, BasePose{}, o), InputError);
}

TEST_CASE("Inequalities combined: rows stacked, each gradient row in its place", "[pareto]") {
  auto a = std::make_shared<ManifoldInequalities>();
  a->count = 1;
  a->tolerance = 1e-3;
  a->eval = [](const BasePose&, const Eigen::VectorXd& th, double* g, double* G) {
    g[0] = th(0);
    if (G) G[0] = 1, G[1] = 0, G[2] = 0;
  };
  auto b = std::make_shared<ManifoldInequalities>();
  b->count = 2;
  b->tolerance = 1e-6;
  b->eval = [](const BasePose&, const Eigen::VectorXd& th, double* g, double* G) {
    g[0] = th(1);
    g[1] = th(0) * th(2);
    if (G) G[0] = 0, G[1] = 1, G[2] = 0, G[3] = th(2), G[4] = 0, G[5] = th(0);
  };
  CHECK(combine_inequalities(nullptr, b) == b);
  CHECK(combine_inequalities(a, nullptr) == a);
  const auto c = combine_inequalities(a, b);
  REQUIRE(c->count == 3);
  CHECK(c->tolerance == 1e-6);
  const Eigen::Vector3d th(2, 3, 5);
  double g[3], G[9];
  c->eval(BasePose{}, th, g, G);
  CHECK(g[0] == 2);
  CHECK(g[1] == 3);
  CHECK(g[2] == 10);
  const double expected[9] = {1, 0, 0, 0, 1, 0, 5, 0, 2};
  for (int i = 0; i < 9; ++i) CHECK(G[i] == expected[i]);
  c->eval(BasePose{}, th, g, nullptr);  // values alone
  CHECK(g[2] == 10);
}

TEST_CASE_METHOD(Paper7Position,
                 "The base-rate constraint: the search's least M_ie within it matches the front's point",
                 "[pareto]") {
  const ParetoFront f = front(12);
  REQUIRE(f.points.size() >= 5);
  const ParetoPoint& mid = f.points[f.points.size() / 2];
  ManifoldSearchOptions so;
  so.starts = 8;
  so.inequalities = base_rate_inequality(pb, s, mid.base_rate);
  const ManifoldSearchResult r = search_capture_manifold(pb, task, s, base, so);
  Data d(m);
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, s.capture.v_in);
  for (const ManifoldPoint& p : r.local_optima)  // every optimum kept keeps the limit
    CHECK(base_disturbance(m, d, base, p.theta, pb.frame, s.capture.target, law).angular_rate() <=
          mid.base_rate * (1 + 1e-5));
  INFO("front point " << mid.M_ie << " kg at " << mid.base_rate << " rad/s, constrained search "
                      << r.best.M_ie << " kg");
  CHECK(r.best.M_ie >= f.min_mass.M_ie * (1 - 1e-9));  // the limit costs M_ie ...
  CHECK(r.best.M_ie <= mid.M_ie * (1 + 1e-3));         // ... no more than the front says
  CHECK(r.best.M_ie >= mid.M_ie * (1 - 1e-2));         // and the front's point is (near) optimal
  CHECK_THROWS_AS(base_rate_inequality(pb, s, -1.0), InputError);
  CHECK_THROWS_AS(base_rate_inequality(pb, s, std::nan("")), InputError);
}

TEST_CASE("max-base-rate-deg: the global run of the 7-DOF scenario within the limit, bad values name the key",
          "[pareto]") {
  ScenarioKeys k = read_scenario_file(kRobots + "paper_7dof_position.toml");
  override_scenario_key(k, "max-base-rate-deg", "1.5e-3");  // the unconstrained global run: 3.2e-3 deg/s
  const Scenario sc = build_scenario(std::move(k));
  const CaptureResult paper = plan_capture(sc.problem, sc.task, sc.capture);
  const GlobalRun g = run_global(sc, paper, sc.objective);
  Data d(*sc.model);
  const double rate = detail::run_base_disturbance(sc, d, g.result.run).angular_rate() * 180 / M_PI;
  INFO("global run: M_ie " << g.result.run.M_ie << " kg, base rate jump " << rate << " deg/s");
  CHECK(g.result.run.capture_distance <= sc.capture.tolerance);
  CHECK(g.result.reached_manifold_optimum);
  CHECK(rate <= 1.5e-3 * 1.01);  // a reached configuration beyond 1 % is planned again (shooting)
  CHECK(g.result.run.M_ie >= 1.2764 * (1 - 1e-3));  // not below the unconstrained optimum
  auto message = [](const std::string& value) {
    ScenarioKeys keys = read_scenario_file(kRobots + "paper_7dof_position.toml");
    try {
      override_scenario_key(keys, "max-base-rate-deg", value);
      build_scenario(std::move(keys));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message("-1").rfind("--max-base-rate-deg: must be positive", 0) == 0);
  CHECK(message("0").rfind("--max-base-rate-deg: must be positive", 0) == 0);
  CHECK(message("nan").rfind("--max-base-rate-deg:", 0) == 0);
  CHECK(message("fast").rfind("--max-base-rate-deg:", 0) == 0);
  // a limit below the front's least rate (the rate end is zero to rounding, 1e-13 deg/s): one line
  ScenarioKeys tight = read_scenario_file(kRobots + "paper_7dof_position.toml");
  override_scenario_key(tight, "max-base-rate-deg", "1e-12");
  const Scenario tight_sc = build_scenario(std::move(tight));
  try {
    run_global(tight_sc, paper, tight_sc.objective);
    FAIL("expected no capture configuration within 1e-12 deg/s");
  } catch (const InputError& e) {
    const std::string w = e.what();
    CHECK(w.rfind("--max-base-rate-deg: no capture configuration found keeps the impact's base-rate jump "
                  "within 1e-12 deg/s",
                  0) == 0);
    CHECK(w.find('\n') == std::string::npos);
  }
}

}  // namespace test_pareto
