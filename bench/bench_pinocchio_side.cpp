// bench/bench_pinocchio_side.cpp -- Pinocchio's CRBA and three routes to u^T J_v M^-1 J_v^T u for
// ffsr-bench-pinocchio. Compiled twice (bench/CMakeLists.txt): FFSR_BENCH_PIN_FACTORY names the
// factory, make_pinocchio_inline (templates instantiated here) or make_pinocchio_library (the
// precompiled libpinocchio_default's, PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION).
#include "bench_pinocchio.hpp"

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/delassus.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/multibody.hpp>

#include <stdexcept>

#ifndef FFSR_BENCH_PIN_FACTORY
#error "FFSR_BENCH_PIN_FACTORY names the factory this unit defines"
#endif

namespace ffsr_bench {
namespace {

volatile double g_pin_sink = 0;

pinocchio::JointIndex add_joint(pinocchio::Model& pm, pinocchio::JointIndex parent, const ffsr::Body& b) {
  using pinocchio::SE3;
  const SE3 placement(b.tree.R, b.tree.p);
  const Eigen::Vector3d& a = b.joint.axis;
  if (b.joint.type == ffsr::JointType::Prismatic)
    return pm.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(a), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitX())
    return pm.addJoint(parent, pinocchio::JointModelRX(), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitY())
    return pm.addJoint(parent, pinocchio::JointModelRY(), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitZ())
    return pm.addJoint(parent, pinocchio::JointModelRZ(), placement, b.joint.name);
  return pm.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(a), placement, b.joint.name);
}

pinocchio::Model build(const ffsr::Model& fm, int frame, pinocchio::FrameIndex& fid) {
  using pinocchio::SE3;
  if (fm.nb() != fm.n() + 1) throw std::runtime_error("pinocchio model: mimic joints are not mapped");
  pinocchio::Model pm;
  const int nb = fm.nb();
  std::vector<pinocchio::JointIndex> jid(static_cast<size_t>(nb));
  auto inertia = [](const ffsr::Inertia& in) { return pinocchio::Inertia(in.mass, in.com, in.I); };
  jid[0] = pm.addJoint(0, pinocchio::JointModelFreeFlyer(), SE3::Identity(), "root");
  pm.appendBodyToJoint(jid[0], inertia(fm.body(0).inertia), SE3::Identity());
  for (int i = 1; i < nb; ++i) {
    const ffsr::Body& b = fm.body(i);
    jid[static_cast<size_t>(i)] = add_joint(pm, jid[static_cast<size_t>(b.parent)], b);
    pm.appendBodyToJoint(jid[static_cast<size_t>(i)], inertia(b.inertia), SE3::Identity());
  }
  const ffsr::Frame& f = fm.frame(frame);
  const pinocchio::JointIndex parent = jid[static_cast<size_t>(f.body)];
  fid = pm.addFrame(pinocchio::Frame("ee_bench", parent, SE3(f.pose.R, f.pose.p), pinocchio::OP_FRAME));
  if (pm.nv != 6 + fm.n()) throw std::runtime_error("pinocchio model: wrong size");
  return pm;
}

class Routes final : public PinocchioRoutes {
 public:
  Routes(const ffsr::Model& fm, int frame, const std::vector<ffsr::BasePose>& base,
         const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& dirs)
      : pm_(build(fm, frame, fid_)), pd_(pm_), u_(dirs), J_(6, pm_.nv), llt_(pm_.nv), w_(pm_.nv), D_(3, 3),
        n_(fm.n()) {
    for (size_t k = 0; k < base.size(); ++k) {
      Eigen::VectorXd qk(pm_.nq);
      qk << base[k].position, base[k].orientation.coeffs(), theta[k];  // x y z, qx qy qz qw, joints
      q_.push_back(qk);
    }
    // the 3-D contact at the frame, its quantities in the contact's axes (LOCAL)
    const pinocchio::Frame& f = pm_.frames[fid_];
    cm_.emplace_back(pinocchio::CONTACT_3D, pm_, f.parentJoint, f.placement, pinocchio::LOCAL);
    cd_.emplace_back(cm_[0]);
  }
  double pass(Kind kind, int count) override;
  double inverse_effective_mass(Kind kind, int k) override {
    return kind == Kind::Delassus ? delassus(k) : dense(k);
  }
  Eigen::MatrixXd joint_block(int k) override {
    pinocchio::crba(pm_, pd_, q_[static_cast<size_t>(k)]);
    pd_.M.triangularView<Eigen::StrictlyLower>() = pd_.M.transpose().triangularView<Eigen::StrictlyLower>();
    return pd_.M.bottomRightCorner(n_, n_);
  }

 private:
  double dense(int k) {
    const auto uk = static_cast<size_t>(k);
    pinocchio::crba(pm_, pd_, q_[uk]);
    pd_.M.triangularView<Eigen::StrictlyLower>() = pd_.M.transpose().triangularView<Eigen::StrictlyLower>();
    J_.setZero();
    pinocchio::computeJointJacobians(pm_, pd_, q_[uk]);
    pinocchio::updateFramePlacements(pm_, pd_);
    pinocchio::getFrameJacobian(pm_, pd_, fid_, pinocchio::LOCAL_WORLD_ALIGNED, J_);
    w_.noalias() = J_.topRows<3>().transpose() * u_[uk];
    llt_.compute(pd_.M);
    return w_.dot(llt_.solve(w_));
  }
  double delassus(int k) {
    const auto uk = static_cast<size_t>(k);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"  // Pinocchio 4.1 marks the API as changing
    pinocchio::computeDelassusMatrix(pm_, pd_, q_[uk], cm_, cd_, D_, 0.0);
#pragma GCC diagnostic pop
    const Eigen::Vector3d uc = cd_[0].oMc1.rotation().transpose() * u_[uk];
    return uc.dot(D_ * uc);
  }

  pinocchio::FrameIndex fid_ = 0;  // before pm_: build() writes it while pm_ is initialized
  pinocchio::Model pm_;
  pinocchio::Data pd_;
  std::vector<Eigen::VectorXd> q_;
  std::vector<Eigen::Vector3d> u_;
  pinocchio::Data::Matrix6x J_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd w_;
  Eigen::MatrixXd D_;
  std::vector<pinocchio::RigidConstraintModel> cm_;
  std::vector<pinocchio::RigidConstraintData> cd_;
  int n_ = 0;
};

double Routes::pass(Kind kind, int count) {
  double acc = 0;
  const double t0 = thread_seconds();
  switch (kind) {
    case Kind::CrbaLocal:
      for (int k = 0; k < count; ++k)
        acc += pinocchio::crba(pm_, pd_, q_[static_cast<size_t>(k)], pinocchio::Convention::LOCAL)(6, 6);
      break;
    case Kind::CrbaLocalFull:
      for (int k = 0; k < count; ++k) {
        pinocchio::crba(pm_, pd_, q_[static_cast<size_t>(k)], pinocchio::Convention::LOCAL);
        pd_.M.triangularView<Eigen::StrictlyLower>() =
            pd_.M.transpose().triangularView<Eigen::StrictlyLower>();
        acc += pd_.M(7, 6);
      }
      break;
    case Kind::CrbaWorld:
      for (int k = 0; k < count; ++k)
        acc += pinocchio::crba(pm_, pd_, q_[static_cast<size_t>(k)], pinocchio::Convention::WORLD)(6, 6);
      break;
    case Kind::Dense:
      for (int k = 0; k < count; ++k) acc += dense(k);
      break;
    case Kind::Delassus:
      for (int k = 0; k < count; ++k) acc += delassus(k);
      break;
  }
  const double t = thread_seconds() - t0;
  g_pin_sink = g_pin_sink + acc;
  return t;
}

}  // namespace

__attribute__((visibility("default"))) std::unique_ptr<PinocchioRoutes> FFSR_BENCH_PIN_FACTORY(
    const ffsr::Model& model, int frame, const std::vector<ffsr::BasePose>& base,
    const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& u) {
  return std::make_unique<Routes>(model, frame, base, theta, u);
}

}  // namespace ffsr_bench
