// bench/bench_pinocchio_side.cpp -- Pinocchio's u^T J_v M^-1 J_v^T u for ffsr-bench-pinocchio.
#include "bench_pinocchio.hpp"

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/multibody.hpp>

#include <algorithm>
#include <ctime>
#include <stdexcept>

namespace ffsr_bench {

double pinocchio_inverse_effective_mass(const ffsr::Model& fm, int frame,
                                        const std::vector<ffsr::BasePose>& base,
                                        const std::vector<Eigen::VectorXd>& theta,
                                        const std::vector<Eigen::Vector3d>& u, int passes,
                                        std::vector<double>& values) {
  using pinocchio::SE3;
  pinocchio::Model pm;
  const int nb = fm.n() + 1;
  std::vector<pinocchio::JointIndex> jid(static_cast<size_t>(nb));
  auto inertia = [](const ffsr::Inertia& in) { return pinocchio::Inertia(in.mass, in.com, in.I); };
  jid[0] = pm.addJoint(0, pinocchio::JointModelFreeFlyer(), SE3::Identity(), "root");
  pm.appendBodyToJoint(jid[0], inertia(fm.body(0).inertia), SE3::Identity());
  for (int i = 1; i < nb; ++i) {
    const ffsr::Body& b = fm.body(i);
    const SE3 placement(b.tree.R, b.tree.p);
    const auto parent = jid[static_cast<size_t>(b.parent)];
    jid[static_cast<size_t>(i)] =
        b.joint.type == ffsr::JointType::Revolute
            ? pm.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(b.joint.axis), placement,
                          b.joint.name)
            : pm.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(b.joint.axis), placement,
                          b.joint.name);
    pm.appendBodyToJoint(jid[static_cast<size_t>(i)], inertia(b.inertia), SE3::Identity());
  }
  const ffsr::Frame& f = fm.frame(frame);
  const auto fid = pm.addFrame(pinocchio::Frame("ee_bench", jid[static_cast<size_t>(f.body)],
                                                SE3(f.pose.R, f.pose.p), pinocchio::OP_FRAME));
  if (pm.nv != 6 + fm.n()) throw std::runtime_error("pinocchio model: wrong size");
  pinocchio::Data pd(pm);
  const int count = static_cast<int>(base.size());
  std::vector<Eigen::VectorXd> q(base.size());
  for (size_t k = 0; k < base.size(); ++k) {
    q[k].resize(pm.nq);
    q[k] << base[k].position, base[k].orientation.coeffs(), theta[k];  // x y z, qx qy qz qw, joints
  }
  pinocchio::Data::Matrix6x J(6, pm.nv);
  Eigen::LLT<Eigen::MatrixXd> llt(pm.nv);
  Eigen::VectorXd w(pm.nv);
  auto eval = [&](int k) {
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
  };
  values.resize(base.size());
  for (int k = 0; k < count; ++k) values[static_cast<size_t>(k)] = eval(k);
  std::vector<double> t;
  double acc = 0;
  for (int r = 0; r < passes; ++r) {
    const double t0 = thread_seconds();
    for (int k = 0; k < count; ++k) acc += eval(k);
    t.push_back((thread_seconds() - t0) / count);
  }
  if (!(acc > 0)) throw std::runtime_error("pinocchio: non-positive inverse effective mass");
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace ffsr_bench
