// bench/bench_pinocchio_side.cpp -- Pinocchio's CRBA and four routes to u^T J_v M^-1 J_v^T u for
// ffsr-bench-pinocchio. Compiled twice (bench/CMakeLists.txt): FFSR_BENCH_PIN_FACTORY names the
// factory, make_pinocchio_inline (templates instantiated here, linked into the bench's executable) or
// make_pinocchio_library (the precompiled libpinocchio_default's, PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION).
#include "bench_pinocchio.hpp"

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/cholesky.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/delassus.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include <stdexcept>

#ifndef FFSR_BENCH_PIN_FACTORY
#error "FFSR_BENCH_PIN_FACTORY names the factory this unit defines"
#endif

namespace ffsr_bench {
namespace {

volatile double g_pin_sink = 0;

/// The model as a Pinocchio user loads it: the URDF text, a free-flyer root joint.
pinocchio::Model load(const std::string& urdf) {
  pinocchio::Model pm;
  pinocchio::urdf::buildModelFromXML(urdf, pinocchio::JointModelFreeFlyer(), pm);
  return pm;
}

class Routes final : public PinocchioRoutes {
 public:
  Routes(const std::string& urdf, const std::string& frame, const std::vector<ffsr::BasePose>& base,
         const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& dirs)
      : pm_(load(urdf)), pd_(pm_), u_(dirs), J_(6, pm_.nv), w_(pm_.nv), D_(3, 3) {
    if (!pm_.existFrame(frame)) throw std::runtime_error("pinocchio model: no frame " + frame);
    fid_ = pm_.getFrameId(frame);
    n_ = pm_.nv - 6;
    for (size_t k = 0; k < base.size(); ++k) {
      if (theta[k].size() != n_) throw std::runtime_error("pinocchio model: wrong number of joints");
      Eigen::VectorXd qk(pm_.nq);
      qk.head<7>() << base[k].position, base[k].orientation.coeffs();  // x y z, qx qy qz qw
      // joint j's velocity index less the base's 6 is its coordinate: the URDF's joints in the same
      // order as ffsr's on these serial robots (the agreement table checks it)
      for (pinocchio::JointIndex j = 2; j < static_cast<pinocchio::JointIndex>(pm_.njoints); ++j) {
        const auto& jm = pm_.joints[j];
        const double angle = theta[k](jm.idx_v() - 6);
        if (jm.nq() == 2)  // an unbounded revolute joint (URDF continuous): (cos q, sin q)
          qk.segment<2>(jm.idx_q()) << std::cos(angle), std::sin(angle);
        else
          qk(jm.idx_q()) = angle;
      }
      q_.push_back(qk);
    }
    J_.setZero();
    // the 3-D contact at the frame, its quantities in the contact's axes (LOCAL)
    const pinocchio::Frame& f = pm_.frames[fid_];
    cm_.emplace_back(pinocchio::CONTACT_3D, pm_, f.parentJoint, f.placement, pinocchio::LOCAL);
    cd_.emplace_back(cm_[0]);
  }
  double pass(Kind kind, int count) override;
  double inverse_effective_mass(Kind kind, int k) override {
    switch (kind) {
      case Kind::DenseWorld:
        return dense_world(k);
      case Kind::Minverse:
        return minverse(k);
      case Kind::Delassus:
        return delassus(k);
      default:
        return dense_local(k);
    }
  }
  Eigen::MatrixXd joint_block(Kind kind, int k) override {
    pinocchio::crba(pm_, pd_, q_[static_cast<size_t>(k)],
                    kind == Kind::CrbaWorld ? pinocchio::Convention::WORLD : pinocchio::Convention::LOCAL);
    pd_.M.triangularView<Eigen::StrictlyLower>() = pd_.M.transpose().triangularView<Eigen::StrictlyLower>();
    return pd_.M.bottomRightCorner(n_, n_);
  }

 private:
  /// w^T M^-1 w = |D^-1/2 U^-1 w|^2 from the factorization M = U D U^T of data.M's upper triangle.
  double factored_form() {
    pinocchio::cholesky::decompose(pm_, pd_);
    pinocchio::cholesky::Uiv(pm_, pd_, w_);
    return w_.cwiseAbs2().dot(pd_.Dinv);
  }
  double dense_local(int k) {
    const auto uk = static_cast<size_t>(k);
    pinocchio::crba(pm_, pd_, q_[uk], pinocchio::Convention::LOCAL);
    pinocchio::computeFrameJacobian(pm_, pd_, q_[uk], fid_, pinocchio::LOCAL_WORLD_ALIGNED, J_);
    w_.noalias() = J_.topRows<3>().transpose() * u_[uk];
    return factored_form();
  }
  double dense_world(int k) {
    const auto uk = static_cast<size_t>(k);
    pinocchio::crba(pm_, pd_, q_[uk], pinocchio::Convention::WORLD);  // also data.J and data.oMi
    pinocchio::getFrameJacobian(pm_, pd_, fid_, pinocchio::LOCAL_WORLD_ALIGNED, J_);
    w_.noalias() = J_.topRows<3>().transpose() * u_[uk];
    return factored_form();
  }
  double minverse(int k) {
    const auto uk = static_cast<size_t>(k);
    pinocchio::computeMinverse(pm_, pd_, q_[uk]);  // upper triangle
    pinocchio::computeFrameJacobian(pm_, pd_, q_[uk], fid_, pinocchio::LOCAL_WORLD_ALIGNED, J_);
    w_.noalias() = J_.topRows<3>().transpose() * u_[uk];
    return w_.dot(pd_.Minv.selfadjointView<Eigen::Upper>() * w_);
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

  pinocchio::Model pm_;
  pinocchio::Data pd_;
  pinocchio::FrameIndex fid_ = 0;
  Eigen::Index n_ = 0;
  std::vector<Eigen::VectorXd> q_;
  std::vector<Eigen::Vector3d> u_;
  pinocchio::Data::Matrix6x J_;
  Eigen::VectorXd w_;
  Eigen::MatrixXd D_;
  std::vector<pinocchio::RigidConstraintModel> cm_;
  std::vector<pinocchio::RigidConstraintData> cd_;
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
    case Kind::DenseLocal:
      for (int k = 0; k < count; ++k) acc += dense_local(k);
      break;
    case Kind::DenseWorld:
      for (int k = 0; k < count; ++k) acc += dense_world(k);
      break;
    case Kind::Minverse:
      for (int k = 0; k < count; ++k) acc += minverse(k);
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
    const std::string& urdf, const std::string& frame, const std::vector<ffsr::BasePose>& base,
    const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& u) {
  return std::make_unique<Routes>(urdf, frame, base, theta, u);
}

}  // namespace ffsr_bench
