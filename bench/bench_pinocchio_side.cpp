// bench/bench_pinocchio_side.cpp -- Pinocchio's CRBA and u^T J_v M^-1 J_v^T u for ffsr-bench-pinocchio.
#include "bench_pinocchio.hpp"

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/multibody.hpp>

#include <stdexcept>

namespace ffsr_bench {
namespace {

volatile double g_pin_sink = 0;

pinocchio::JointIndex add_joint(pinocchio::Model& pm, pinocchio::JointIndex parent, const ffsr::Body& b) {
  using pinocchio::SE3;
  const SE3 placement(b.tree.R, b.tree.p);
  const Eigen::Vector3d& a = b.joint.axis;
  if (b.joint.type == ffsr::JointType::Prismatic)
    return pm.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(a), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitX()) return pm.addJoint(parent, pinocchio::JointModelRX(), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitY()) return pm.addJoint(parent, pinocchio::JointModelRY(), placement, b.joint.name);
  if (a == Eigen::Vector3d::UnitZ()) return pm.addJoint(parent, pinocchio::JointModelRZ(), placement, b.joint.name);
  return pm.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(a), placement, b.joint.name);
}

}  // namespace

struct PinocchioBench::Impl {
  pinocchio::FrameIndex fid = 0;  // before pm: build() writes it while pm is initialized
  pinocchio::Model pm;
  pinocchio::Data pd;
  std::vector<Eigen::VectorXd> q;
  std::vector<Eigen::Vector3d> u;
  pinocchio::Data::Matrix6x J;
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd w;
  int n = 0;

  static pinocchio::Model build(const ffsr::Model& fm, int frame, pinocchio::FrameIndex& fid) {
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
    fid = pm.addFrame(pinocchio::Frame("ee_bench", jid[static_cast<size_t>(f.body)], SE3(f.pose.R, f.pose.p),
                                       pinocchio::OP_FRAME));
    if (pm.nv != 6 + fm.n()) throw std::runtime_error("pinocchio model: wrong size");
    return pm;
  }
  Impl(const ffsr::Model& fm, int frame, const std::vector<ffsr::BasePose>& base,
       const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& dirs)
      : pm(build(fm, frame, fid)), pd(pm), u(dirs), J(6, pm.nv), llt(pm.nv), w(pm.nv), n(fm.n()) {
    for (size_t k = 0; k < base.size(); ++k) {
      Eigen::VectorXd qk(pm.nq);
      qk << base[k].position, base[k].orientation.coeffs(), theta[k];  // x y z, qx qy qz qw, joints
      q.push_back(qk);
    }
  }
  double eval(int k) {
    const auto uk = static_cast<size_t>(k);
    pinocchio::crba(pm, pd, q[uk]);
    pd.M.triangularView<Eigen::StrictlyLower>() = pd.M.transpose().triangularView<Eigen::StrictlyLower>();
    J.setZero();
    pinocchio::computeJointJacobians(pm, pd, q[uk]);
    pinocchio::updateFramePlacements(pm, pd);
    pinocchio::getFrameJacobian(pm, pd, fid, pinocchio::LOCAL_WORLD_ALIGNED, J);
    w.noalias() = J.topRows<3>().transpose() * u[uk];
    llt.compute(pd.M);
    return w.dot(llt.solve(w));
  }
};

PinocchioBench::PinocchioBench(const ffsr::Model& model, int frame, const std::vector<ffsr::BasePose>& base,
                               const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& u)
    : impl_(std::make_unique<Impl>(model, frame, base, theta, u)) {}

PinocchioBench::~PinocchioBench() = default;

double PinocchioBench::pass(Kind kind, int count) {
  Impl& m = *impl_;
  double acc = 0;
  const double t0 = thread_seconds();
  switch (kind) {
    case Kind::CrbaLocal:
      for (int k = 0; k < count; ++k)
        acc += pinocchio::crba(m.pm, m.pd, m.q[static_cast<size_t>(k)], pinocchio::Convention::LOCAL)(6, 6);
      break;
    case Kind::CrbaLocalFull:
      for (int k = 0; k < count; ++k) {
        pinocchio::crba(m.pm, m.pd, m.q[static_cast<size_t>(k)], pinocchio::Convention::LOCAL);
        m.pd.M.triangularView<Eigen::StrictlyLower>() =
            m.pd.M.transpose().triangularView<Eigen::StrictlyLower>();
        acc += m.pd.M(7, 6);
      }
      break;
    case Kind::CrbaWorld:
      for (int k = 0; k < count; ++k)
        acc += pinocchio::crba(m.pm, m.pd, m.q[static_cast<size_t>(k)], pinocchio::Convention::WORLD)(6, 6);
      break;
    case Kind::InverseEffectiveMass:
      for (int k = 0; k < count; ++k) acc += m.eval(k);
      break;
  }
  const double t = thread_seconds() - t0;
  g_pin_sink = g_pin_sink + acc;
  return t;
}

double PinocchioBench::inverse_effective_mass(int k) { return impl_->eval(k); }

Eigen::MatrixXd PinocchioBench::joint_block(int k) {
  Impl& m = *impl_;
  pinocchio::crba(m.pm, m.pd, m.q[static_cast<size_t>(k)]);
  m.pd.M.triangularView<Eigen::StrictlyLower>() = m.pd.M.transpose().triangularView<Eigen::StrictlyLower>();
  return m.pd.M.bottomRightCorner(m.n, m.n);
}

}  // namespace ffsr_bench
