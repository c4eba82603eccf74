// The onboard blob and the C interface of the controllers (include/ffsr/onboard.h): the blob read back
// is the problem bit for bit, the C interface's commands are the C++ controllers' on the same states,
// its plant model follows the CVODE run, and every defect of a blob or a step's input gives its status.
#include "ffsr/control/onboard_blob.hpp"
#include "ffsr/jobs/detumble.hpp"
#include "ffsr/onboard.h"
#include "ffsr/scenario/scenario.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace test_onboard {

using namespace ffsr;

const std::string kRobots = std::string(FFSR_SOURCE_DIR) + "/robots/";

std::vector<double> capture_blob_of(const Scenario& sc) {
  CaptureOptions opt = sc.capture;
  opt.hold_base_attitude = sc.hold_base_attitude;
  return capture_blob(sc.problem, sc.task, opt);
}

struct DetumbleCase {
  Scenario sc;
  DetumbleJobResult job;
  Model stack;
  std::vector<double> blob;
  explicit DetumbleCase(const std::string& file) : sc(load_scenario(file)), job(detumble(sc)) {
    const Model& m = *sc.model;
    stack = attach_body(m, m.frame(sc.problem.frame).name, job.grasp.body);
    const DetumbleSettings& s = job.settings;
    blob = detumble_blob(stack, sc.problem.frame, job.grasp.body, s.limits, s.options, s.run.tick, job.start);
  }
};

/// The blob's checksum made to hold again after an entry was changed (a defect behind a valid checksum).
void reseal(std::vector<double>& b) {
  const std::uint64_t h = detail::blob_checksum(b.data() + kOnboardBlobHeader, b.size() - kOnboardBlobHeader);
  b[4] = static_cast<double>(h >> 32);
  b[5] = static_cast<double>(h & 0xffffffffULL);
}

double relative_gap(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1e-300, b.cwiseAbs().maxCoeff());
}

TEST_CASE("onboard blob: the capture problem read back bit for bit, for both paper robots") {
  for (const char* file : {"paper_3dof.toml", "paper_7dof_position.toml"}) {
    const Scenario sc = load_scenario(kRobots + file);
    const std::vector<double> blob = capture_blob_of(sc);
    CaptureBlob back;
    REQUIRE(read_capture_blob(blob.data(), blob.size(), back) == BlobStatus::Ok);
    const Model& a = *sc.model;
    const Model& b = back.model;
    REQUIRE(b.nb() == a.nb());
    REQUIRE(b.n() == a.n());
    REQUIRE(b.frames().size() == a.frames().size());
    CHECK(b.end_effector() == a.end_effector());
    for (int i = 0; i < a.nb(); ++i) {
      CHECK(b.body(i).parent == a.body(i).parent);
      CHECK(b.body(i).tree.p == a.body(i).tree.p);
      CHECK(b.body(i).tree.R == a.body(i).tree.R);
      CHECK(b.body(i).joint.axis == a.body(i).joint.axis);
      CHECK(b.body(i).inertia.mass == a.body(i).inertia.mass);
      CHECK(b.body(i).inertia.com == a.body(i).inertia.com);
      CHECK(b.body(i).inertia.I == a.body(i).inertia.I);
      CHECK(b.body(i).coord == a.body(i).coord);
    }
    for (int k = 0; k < a.n(); ++k) {
      CHECK(b.joint(k).lower == a.joint(k).lower);
      CHECK(b.joint(k).upper == a.joint(k).upper);
    }
    const CaptureProblem& p = back.problem;
    CHECK(p.frame == sc.problem.frame);
    CHECK(p.theta == sc.problem.theta);
    CHECK(p.law == sc.problem.law);
    CHECK(p.target.angular_velocity == sc.problem.target.angular_velocity);
    CHECK(p.target.inertia == sc.problem.target.inertia);
    CHECK(back.options.duration == sc.capture.duration);
    CHECK(back.options.gain == sc.capture.gain);
    CHECK(back.task.rows() == sc.task.rows());
  }
}

TEST_CASE("onboard C interface: the capture commands are the C++ controller's along a closed loop") {
  for (const char* file : {"paper_3dof.toml", "paper_7dof_position.toml"}) {
    const Scenario sc = load_scenario(kRobots + file);
    const std::vector<double> blob = capture_blob_of(sc);
    ffsr_capture* c = nullptr;
    REQUIRE(ffsr_capture_init(blob.data(), blob.size(), &c) == FFSR_OK);
    const int n = ffsr_capture_joints(c);
    REQUIRE(n == sc.model->n());
    CaptureOptions opt = sc.capture;
    opt.hold_base_attitude = sc.hold_base_attitude;
    auto ref = make_gradient_controller(sc.problem, sc.task, opt);
    ControlCommand want = ref.make_command();
    ffsr_capture_state s{};
    ffsr_target_estimate e{};
    REQUIRE(ffsr_capture_start(c, &s, &e) == FFSR_OK);
    ffsr_capture_command got{};
    const double T = ffsr_capture_duration(c), dt = T / 400;
    double worst = 0;
    for (int tick = 0; tick < 400; ++tick) {
      const double t = tick * dt;
      REQUIRE(ffsr_capture_step(c, t, &s, &e, &got) == FFSR_OK);
      ControllerState cs{{Vector3(s.base_position[0], s.base_position[1], s.base_position[2]),
                          Quaternion(s.base_orientation[0], s.base_orientation[1], s.base_orientation[2],
                                     s.base_orientation[3])},
                         Eigen::Map<const Eigen::VectorXd>(s.theta, n)};
      ref.step(t, cs, target_estimate(sc.problem.target), want);
      REQUIRE(want.status != ControlStatus::Fault);
      worst = std::max(worst, relative_gap(Eigen::Map<const Eigen::VectorXd>(got.theta_dot, n), want.theta_dot));
      worst = std::max(worst, relative_gap(Eigen::Map<const Eigen::VectorXd>(got.base_velocity, 6), want.base_velocity));
      CHECK(got.status == static_cast<int>(want.status));
      for (int k = 0; k < n; ++k) s.theta[k] += dt * got.theta_dot[k];
      for (int i = 0; i < 3; ++i) s.base_position[i] += dt * got.base_velocity[i];
    }
    INFO(file << ": largest relative gap " << worst);
    CHECK(worst <= 1e-14);
    ffsr_capture_free(c);
  }
}

TEST_CASE("onboard C interface: the detumble commands are DetumbleController's, its plant follows CVODE") {
  const DetumbleCase dc(kRobots + "paper_7dof_detumble.toml");
  ffsr_detumble* d = nullptr;
  REQUIRE(ffsr_detumble_init(dc.blob.data(), dc.blob.size(), &d) == FFSR_OK);
  const int n = ffsr_detumble_joints(d);
  REQUIRE(n == 7);
  const DetumbleSettings& set = dc.job.settings;
  REQUIRE(ffsr_detumble_tick(d) == set.run.tick);
  DetumbleController ref(dc.stack, dc.sc.problem.frame, dc.job.grasp.body, set.limits, set.options, set.run.tick);
  DetumbleCommand want = ref.make_command();
  ffsr_detumble_state s{}, next{};
  REQUIRE(ffsr_detumble_start(d, &s) == FFSR_OK);
  ffsr_detumble_command got{};
  const auto& series = dc.job.result.series;
  const int ticks = std::min<int>(100, static_cast<int>(series.size()));
  double worst = 0, drift = 0, peak = 0;
  for (int tick = 0; tick < ticks; ++tick) {
    REQUIRE(ffsr_detumble_step(d, &s, &got) == FFSR_OK);
    DetumbleState cs = dc.job.start;
    cs.base.position = Vector3(s.base_position[0], s.base_position[1], s.base_position[2]);
    cs.base.orientation =
        Quaternion(s.base_orientation[0], s.base_orientation[1], s.base_orientation[2], s.base_orientation[3]);
    cs.theta = Eigen::Map<const Eigen::VectorXd>(s.theta, n);
    cs.v = Eigen::Map<const Eigen::VectorXd>(s.velocity, 6 + n);
    ref.step(cs, want);
    worst = std::max(worst, relative_gap(Eigen::Map<const Eigen::VectorXd>(got.tau, n), want.tau));
    CHECK(got.status == static_cast<int>(want.status));
    // the plant model one tick ahead against CVODE's run of the same command (the job's series)
    const DetumbleSample& at = series[static_cast<size_t>(tick)];
    drift = std::max(drift, (cs.v.tail(n) - at.theta_dot).cwiseAbs().maxCoeff());
    peak = std::max(peak, at.theta_dot.cwiseAbs().maxCoeff());
    REQUIRE(ffsr_detumble_predict(d, &s, &got, ffsr_detumble_tick(d), &next) == FFSR_OK);
    s = next;
  }
  INFO("largest relative gap of the torques " << worst << ", of the rates from CVODE's " << drift / peak);
  CHECK(worst <= 1e-14);
  CHECK(drift <= 1e-6 * peak);  // one Runge-Kutta step a tick against CVODE at rtol 1e-12
  ffsr_detumble_free(d);
}

TEST_CASE("onboard C interface: every defect of a blob gives its own status, and nothing is built") {
  const Scenario sc = load_scenario(kRobots + "paper_3dof.toml");
  const std::vector<double> good = capture_blob_of(sc);
  ffsr_capture* c = reinterpret_cast<ffsr_capture*>(&c);  // must come back NULL
  const auto init = [&](const std::vector<double>& b) {
    const ffsr_status s = ffsr_capture_init(b.data(), b.size(), &c);
    CHECK(c == nullptr);
    return s;
  };
  std::vector<double> b = good;
  b.resize(5);
  CHECK(init(b) == FFSR_ERR_BLOB_SHORT);
  b = good;
  b[0] = 1;
  CHECK(init(b) == FFSR_ERR_BLOB_MAGIC);
  b = good;
  b[1] = 2;
  CHECK(init(b) == FFSR_ERR_BLOB_VERSION);
  b = good;
  b[2] = 2;
  CHECK(init(b) == FFSR_ERR_BLOB_KIND);
  b = good;
  b.pop_back();
  CHECK(init(b) == FFSR_ERR_BLOB_COUNT);
  b = good;
  b[40] = std::nextafter(b[40], 1e300);  // one ulp anywhere
  CHECK(init(b) == FFSR_ERR_BLOB_CHECKSUM);
  b = good;
  b[20] = std::numeric_limits<double>::quiet_NaN();
  reseal(b);
  CHECK(init(b) == FFSR_ERR_BLOB_NOT_FINITE);
  b = good;
  b[8] = 1000;  // bodies
  reseal(b);
  CHECK(init(b) == FFSR_ERR_BLOB_LAYOUT);
  b = good;
  b[8] = 2.5;  // not an integer
  reseal(b);
  CHECK(init(b) == FFSR_ERR_BLOB_LAYOUT);
  b = good;
  b.push_back(0);  // a trailing entry
  b[3] = static_cast<double>(b.size());
  reseal(b);
  CHECK(init(b) == FFSR_ERR_BLOB_LAYOUT);
  ffsr_detumble* d = nullptr;
  CHECK(ffsr_detumble_init(good.data(), good.size(), &d) == FFSR_ERR_BLOB_KIND);
  CHECK(d == nullptr);
  CHECK(ffsr_capture_init(nullptr, 0, &c) == FFSR_ERR_BLOB_SHORT);
  CHECK(ffsr_capture_init(good.data(), good.size(), nullptr) == FFSR_ERR_ARGUMENT);
  CHECK(std::string(ffsr_status_name(FFSR_ERR_BLOB_CHECKSUM)) == "blob checksum");
}

TEST_CASE("onboard C interface: a bad input of a step is refused naming its field, the command zeroed") {
  const Scenario sc = load_scenario(kRobots + "paper_3dof.toml");
  const std::vector<double> blob = capture_blob_of(sc);
  ffsr_capture* c = nullptr;
  REQUIRE(ffsr_capture_init(blob.data(), blob.size(), &c) == FFSR_OK);
  ffsr_capture_state s{};
  ffsr_target_estimate e{};
  REQUIRE(ffsr_capture_start(c, &s, &e) == FFSR_OK);
  ffsr_capture_command out{};
  REQUIRE(ffsr_capture_step(c, 0.0, &s, &e, &out) == FFSR_OK);
  ffsr_capture_state bad = s;
  bad.theta[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK(ffsr_capture_step(c, 1.0, &bad, &e, &out) == FFSR_ERR_FAULT);
  CHECK(out.fault == static_cast<int>(ControlFault::JointAngle));
  CHECK(out.fault_index == 1);
  CHECK(out.theta_dot[0] == 0.0);
  bad = s;
  bad.base_orientation[0] = 2;
  CHECK(ffsr_capture_step(c, 1.0, &bad, &e, &out) == FFSR_ERR_FAULT);
  CHECK(out.fault == static_cast<int>(ControlFault::BaseQuaternionNorm));
  CHECK(ffsr_capture_step(c, -1.0, &s, &e, &out) == FFSR_ERR_FAULT);
  CHECK(out.fault == static_cast<int>(ControlFault::Time));
  ffsr_target_estimate eb = e;
  eb.velocity[2] = std::numeric_limits<double>::infinity();
  int fault = 0;
  CHECK(ffsr_capture_update_target(c, 1.0, &eb, &fault) == FFSR_ERR_FAULT);
  CHECK(fault == static_cast<int>(ControlFault::TargetVelocity));
  CHECK(ffsr_capture_step(c, 1.0, nullptr, &e, &out) == FFSR_ERR_ARGUMENT);
  ffsr_capture_free(c);

  const DetumbleCase dc(kRobots + "paper_7dof_detumble.toml");
  ffsr_detumble* d = nullptr;
  REQUIRE(ffsr_detumble_init(dc.blob.data(), dc.blob.size(), &d) == FFSR_OK);
  ffsr_detumble_state ds{};
  REQUIRE(ffsr_detumble_start(d, &ds) == FFSR_OK);
  ffsr_detumble_command dcmd{};
  ds.velocity[9] = std::numeric_limits<double>::quiet_NaN();
  CHECK(ffsr_detumble_step(d, &ds, &dcmd) == FFSR_ERR_FAULT);
  CHECK(dcmd.fault == static_cast<int>(DetumbleFault::Velocity));
  CHECK(dcmd.tau[0] == 0.0);
  ffsr_detumble_state next{};
  CHECK(ffsr_detumble_predict(d, &ds, &dcmd, -1.0, &next) == FFSR_ERR_ARGUMENT);
  ffsr_detumble_free(d);
}

}  // namespace test_onboard
