// The front of (M_ie, base angular rate jump) on the capture manifold (optimize/pareto.hpp).
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/io/urdf.hpp"
#include "ffsr/optimize/pareto.hpp"

namespace test_pareto {

using namespace ffsr;
using ffsr::test::kRobots;

TEST_CASE("Pareto front of M_ie and the base rate jump: non-dominated, on the manifold, ends optimal",
          "[pareto]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb = ffsr::test::problem_7dof(m);
  pb.contact = ffsr::test::kPaperContact;
  CaptureTask task;  // position
  CaptureOptions opt;
  opt.duration = 157;
  const CaptureSetup s = prepare_capture(pb, task, opt);
  const BasePose base;  // the initial base pose
  ParetoOptions o;
  o.starts = 8;
  o.levels = 24;
  const ParetoFront f = pareto_front(pb, task, s, base, o);
  INFO("points " << f.points.size() << " ends " << f.min_mass.M_ie << " kg / " << f.min_mass.base_rate
                 << " rad/s and " << f.min_rate.M_ie << " kg / " << f.min_rate.base_rate << " rad/s, hv "
                 << f.hypervolume_normalized);
  CHECK(f.points.size() >= 20);
  Data d(m);
  Eigen::VectorXd r;
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, s.v_in);
  for (size_t i = 0; i < f.points.size(); ++i) {
    const ParetoPoint& p = f.points[i];
    if (i > 0) {  // M_ie increasing, rate decreasing: no point dominates another
      CHECK(p.M_ie > f.points[i - 1].M_ie);
      CHECK(p.base_rate < f.points[i - 1].base_rate);
    }
    capture_residual(m, d, pb, task, s, base, p.theta, r, nullptr);
    CHECK(r.norm() < 1e-9);
    // the rate again, through the whole-configuration function (target at T, the law at delta_dot^-)
    const BaseDisturbance bd = base_disturbance(m, d, base, p.theta, pb.frame, s.capture_target, law);
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

}  // namespace test_pareto
