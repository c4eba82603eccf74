// The capture controller does not touch the heap after its construction: global operator new and
// delete are replaced by counting versions, and so are malloc, calloc, realloc, free and the aligned
// allocations (glibc: interposed, forwarding to __libc_malloc and friends), since Eigen allocates
// with malloc, not new (which is why this is an executable of its own).

#include <atomic>
#include <cstdlib>
#include <malloc.h>
#include <new>
#if defined(__clang__) && defined(__SSE__)
// clang's <mm_malloc.h> (through Eigen's SSE intrinsics) declares posix_memalign again without noexcept;
// clang accepts that after glibc's declaration but not after the definition below, so it comes first
#include <mm_malloc.h>
#endif

// 1e5 calls of step() on the paper's 3-DOF and 7-DOF robots (gradient and servo policies, position
// and pose tasks, a few faults among them) must count zero allocations and zero frees. A control case
// checks that the counters see both a `new` and an Eigen allocation.

namespace {
std::atomic<long> g_news{0}, g_deletes{0};
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
void* malloc(std::size_t size) noexcept {
  ++g_news;
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) noexcept {
  ++g_news;
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  ++g_news;
  return __libc_realloc(p, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  ++g_news;
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  ++g_news;
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  ++g_news;
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : 12;  // ENOMEM
}
void free(void* p) noexcept {
  if (p) ++g_deletes;
  __libc_free(p);
}
}

// new and delete count once (through malloc and free)
void* operator new(std::size_t size) {
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& t) noexcept { return operator new(size, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { operator delete(p); }
void operator delete(void* p, std::size_t) noexcept { operator delete(p); }
void operator delete[](void* p, std::size_t) noexcept { operator delete(p); }

#include <catch2/catch.hpp>

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/detumble_controller.hpp"
#include "ffsr/control/detumble_replay.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace test_controller_alloc {

using namespace ffsr;

namespace {

const std::string kRobots = std::string(FFSR_SOURCE_DIR) + "/robots/";

struct Count {
  long news, deletes;
};

/// 1e5 ticks over [0, T] with a state that moves a little from tick to tick; every 1000th tick has a
/// NaN joint angle (the fault path). Returns the allocations and frees counted during the loop.
template <class Policy>
Count count_ticks(CaptureController<Policy>& ctrl, const CaptureProblem& pb, long& faults, long& rated) {
  ControlCommand cmd = ctrl.make_command();
  ControllerState st{pb.base, pb.theta};
  const TargetEstimate est = target_estimate(pb.target);
  const double T = ctrl.duration();
  const long ticks = 100000;
  const long n0 = g_news.load(), d0 = g_deletes.load();
  for (long k = 0; k < ticks; ++k) {
    const double t = T * static_cast<double>(k) / static_cast<double>(ticks);
    for (Eigen::Index j = 0; j < st.theta.size(); ++j)
      st.theta(j) = pb.theta(j) + 1e-3 * std::sin(1e-3 * static_cast<double>(k) + static_cast<double>(j));
    if (k % 1000 == 999) st.theta(0) = std::nan("");
    ctrl.step(t, st, est, cmd);
    if (cmd.status == ControlStatus::Fault)
      ++faults;
    else if (cmd.theta_dot.allFinite())
      ++rated;
  }
  return {g_news.load() - n0, g_deletes.load() - d0};
}

}  // namespace

TEST_CASE("controller: 1e5 ticks allocate nothing (3-DOF and 7-DOF, gradient and servo)") {
  for (const char* name : {"paper_3dof", "paper_7dof_position", "paper_7dof_pose"}) {
    CAPTURE(name);
    const Scenario sc = load_scenario(kRobots + name + ".toml");
    auto paper = make_gradient_controller(sc.problem, sc.task, sc.capture);
    long faults = 0, rated = 0;
    const Count c = count_ticks(paper, sc.problem, faults, rated);
    CHECK(c.news == 0);
    CHECK(c.deletes == 0);
    CHECK(faults == 100);
    CHECK(rated == 100000 - 100);
    CaptureOptions g = sc.capture;
    g.max_joint_rate = 3 * M_PI / 180;
    Eigen::VectorXd goal = sc.problem.theta;
    goal(0) += 0.3;
    auto servo = make_servo_controller(sc.problem, sc.task, g, goal);
    faults = rated = 0;
    const Count s = count_ticks(servo, sc.problem, faults, rated);
    CHECK(s.news == 0);
    CHECK(s.deletes == 0);
    CHECK(faults == 100);
  }
}

TEST_CASE("detumble controller: 1e5 ticks allocate nothing (7-DOF stack, each actuator, each law)") {
  const Model robot = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  AttachedBody body;
  body.mass = 200;
  body.inertia = Vector3(100, 80, 120).asDiagonal();
  body.pose.p = Vector3(0.3, -0.1, 0.2);
  const Model stack = attach_body(robot, "ee", body);
  // the modes: the exact law with the joint limits, with the gripper's limits too, the passive law
  for (int mode = 0; mode < 3; ++mode)
  for (const BaseActuator a : {BaseActuator::None, BaseActuator::ReactionWheels, BaseActuator::Thrusters}) {
    CAPTURE(mode);
    CAPTURE(static_cast<int>(a));
    DetumbleLimits lim;
    if (mode == 1) {
      lim.gripper_force = 20;
      lim.gripper_moment = 10;
    }
    lim.joint_torque = Eigen::VectorXd::Constant(7, 5.0);
    lim.actuator = a;
    lim.wheel_torque = 0.2;
    lim.wheel_momentum = 1;
    lim.thruster_force = 2;
    lim.thruster_torque = 0.2;
    DetumbleOptions opt;
    opt.stop_stack_spin = a != BaseActuator::None;
    opt.hold = mode != 2;
    DetumbleController ctrl(stack, stack.frame_index("ee"), body, lim, opt);
    DetumbleCommand cmd = ctrl.make_command();
    DetumbleState st{BasePose{}, Eigen::VectorXd::Constant(7, 0.4), Eigen::VectorXd::Constant(13, 0.05),
                     Vector3(0.5, -2.0, 0.1)};
    long faults = 0, saturated = 0, passive = 0;
    const long n0 = g_news.load(), d0 = g_deletes.load();
    for (long k = 0; k < 100000; ++k) {
      for (Eigen::Index j = 0; j < 7; ++j)
        st.theta(j) = 0.4 + 0.5 * std::sin(1e-3 * static_cast<double>(k + j));
      st.v(8) = (k % 1000 == 999) ? std::nan("") : 0.05;
      ctrl.step(st, cmd);
      faults += cmd.status == DetumbleStatus::Fault;
      saturated += cmd.status == DetumbleStatus::Saturated;
      passive += cmd.passive;
    }
    CHECK(g_news.load() - n0 == 0);
    CHECK(g_deletes.load() - d0 == 0);
    CHECK(faults == 100);
    CHECK(saturated > 0);
    if (mode == 2) CHECK(passive == 100000 - faults);
  }
  // the centroidal momentum the step's base wrench reads (from H): none either
  Data d(stack);
  crba(stack, d, BasePose{}, Eigen::VectorXd::Constant(7, 0.4));
  const Eigen::VectorXd v = Eigen::VectorXd::Constant(13, 0.05);
  double sum = 0;
  const long n0 = g_news.load(), d0 = g_deletes.load();
  for (long k = 0; k < 100000; ++k) sum += centroidal_momentum(stack, d, v).angular.norm();
  CHECK(g_news.load() - n0 == 0);
  CHECK(g_deletes.load() - d0 == 0);
  CHECK(sum > 0);
}

TEST_CASE("detumble plan tracker: 1e5 ticks allocate nothing (7-DOF stack, thrusters or free-floating, gripper limits)") {
  const Model robot = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  AttachedBody body;
  body.mass = 200;
  body.inertia = Vector3(100, 80, 120).asDiagonal();
  body.pose.p = Vector3(0.3, -0.1, 0.2);
  const Model stack = attach_body(robot, "ee", body);
  DetumbleLimits lim;
  lim.joint_torque = Eigen::VectorXd::Constant(7, 5.0);
  lim.actuator = BaseActuator::Thrusters;
  lim.thruster_force = 2;
  lim.thruster_torque = 0.2;
  lim.gripper_force = 20;
  lim.gripper_moment = 10;
  DetumbleOptions opt;
  opt.stop_stack_spin = true;
  // the feedback through H with thrusters, through H* (the base free) without an actuator
  const bool free_floating = GENERATE(false, true);
  if (free_floating) {
    lim.actuator = BaseActuator::None;
    opt.stop_stack_spin = false;
  }
  // a plan of 20 intervals of 0.05 s through the state the ticks measure (tracked: within its band)
  DetumbleState st{BasePose{}, Eigen::VectorXd::Constant(7, 0.4), Eigen::VectorXd::Constant(13, 0.05),
                   Vector3::Zero()};
  DetumblePlan plan;
  plan.duration = 1.0;
  plan.nodes.assign(21, st);
  plan.tau.assign(20, Eigen::VectorXd::Constant(7, 0.5));
  plan.base_wrench.assign(20, (Vector6() << 0.5, 0, 0, 0, 0.05, 0).finished());
  DetumblePlanTracker tracker(stack, stack.frame_index("ee"), body, plan, lim, opt, 0.01);
  DetumbleCommand cmd = tracker.make_command();
  long faults = 0, tracking = 0;
  const long n0 = g_news.load(), d0 = g_deletes.load();
  for (long k = 0; k < 100000; ++k) {
    for (Eigen::Index j = 0; j < 7; ++j) st.theta(j) = 0.4 + 0.05 * std::sin(1e-3 * static_cast<double>(k + j));
    st.v(8) = (k % 1000 == 999) ? std::nan("") : 0.05;
    tracker.step(st, 0.01 * static_cast<double>(k % 100), cmd);
    faults += cmd.status == DetumbleStatus::Fault;
    tracking += cmd.tracking;
  }
  CHECK(g_news.load() - n0 == 0);
  CHECK(g_deletes.load() - d0 == 0);
  CHECK(faults == 100);
  CHECK(tracking > 50000);
  CHECK(!tracker.fell_back());
}

TEST_CASE("controller: the counters see new and Eigen's allocations (control)") {
  long n0 = g_news.load(), d0 = g_deletes.load();
  {
    Eigen::VectorXd v(1000);
    v.setZero();
    CHECK(v.sum() == 0);
  }
  CHECK(g_news.load() - n0 == 1);
  CHECK(g_deletes.load() - d0 == 1);
  n0 = g_news.load();
  d0 = g_deletes.load();
  auto p = std::make_unique<std::vector<int>>(100, 1);
  CHECK(p->size() == 100);
  p.reset();
  CHECK(g_news.load() - n0 == 2);
  CHECK(g_deletes.load() - d0 == 2);
}

}  // namespace test_controller_alloc
