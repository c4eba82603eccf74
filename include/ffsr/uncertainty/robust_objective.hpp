// ffsr/uncertainty/robust_objective.hpp -- a tail measure of the maximum contact force over a fixed
// set of uncertain samples, with its gradient in the joint angles: the objective "robust-force" of
// the global capture search (optimize/global.hpp). Eigen only.
#pragma once

#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

// The measure. For a capture configuration (base pose and joint angles at T) and samples i = 1..N
// (uncertainty/sampling.hpp), F_i is the exact single-body peak (Eq. 16) of sample i. The objective
// is the conditional value at risk at 95 % (CVaR_95): the mean of the k = ceil(N / 20) largest F_i.
// CVaR bounds the 95th percentile from above, is continuous in the configuration (the percentile
// jumps from one sample to another) and its gradient is the mean of the tail samples' gradients,
// which SLSQP can use. The 95th percentile (nearest rank) is reported beside it.
//
// The force of a sample as a function of the configuration. With Lambda^-1 = J H^-1 J^T the robot's
// 6x6 inverse inertia at the end-effector and s_i = [u_i; rho_i x u_i] the sample's unit force at
// its contact point (sampling.hpp),
//   M_i = 1 / (s_i^T Lambda^-1 s_i + b_i),   b_i the target's inverse mass along u_i (sample constant),
// and the exact peak of Eq. 16 scales as F_i = c_i M_i^(a_i / (a_i + 1)) (a_i the contact exponent):
// in Eq. 16 with delta = L x, t = L / v s (v = delta_dot^-) the mass enters only through
// L^(a + 1) = M v^2 / K (the damping factor depends on c_r and v only, Table 1), and F = K L^a.
// So c_i = F_i(1 kg) is computed once per sample by the exact peak, and a configuration costs one
// Lambda^-1 and N evaluations of c_i M_i^p_i -- no peak solve per evaluation (test_uncertainty
// checks the scaling against the exact peak for the eight laws).
//
// The gradient. dF_i = p_i F_i / M_i dM_i and dM_i = -M_i^2 d(s_i^T Lambda^-1 s_i), so the gradient
// of CVaR_95 is d tr(Lambda^-1 W) with W = sum over the tail of w_i s_i s_i^T, w_i = -p_i F_i M_i / k.
// W is a symmetric 6x6 matrix: with its eigen-decomposition W = sum_j l_j e_j e_j^T the gradient is
// sum_j l_j d(e_j^T Lambda^-1 e_j), six analytic form gradients (effective_mass_gradient.hpp,
// inverse_inertia_form_gradient) whatever the number of samples.

namespace ffsr {

/// CVaR_95 of the exact F_max over a fixed sample set (see the notes after the includes). Holds scratch
/// buffers: one object per thread.
class RobustForceObjective {
 public:
  /// `law` names the damping law (Table 1). InputError for an empty sample set or a bad law.
  RobustForceObjective(std::vector<UncertainSample> samples, std::string law)
      : samples_(std::move(samples)), law_(std::move(law)) {
    if (samples_.empty()) FFSR_THROW(InputError("RobustForceObjective: no samples"));
    c_.resize(samples_.size());
    p_.resize(samples_.size());
    for (std::size_t i = 0; i < samples_.size(); ++i) {
      const UncertainSample& s = samples_[i];
      c_[i] = max_force_exact(make_contact_law(law_, s.contact, s.approach_velocity), 1.0);
      p_[i] = s.contact.alpha / (s.contact.alpha + 1.0);
    }
    tail_ = (samples_.size() + 19) / 20;
    F_.resize(samples_.size());
    M_.resize(samples_.size());
    order_.resize(samples_.size());
  }

  const std::vector<UncertainSample>& samples() const { return samples_; }
  const std::string& law() const { return law_; }
  /// k = ceil(N / 20): the samples averaged by CVaR_95.
  std::size_t tail_count() const { return tail_; }

  struct Value {
    double cvar95 = 0;  ///< mean of the tail_count() largest F_max, N
    double p95 = 0;     ///< 95th percentile (nearest rank), N
  };

  /// The measure for a configuration with robot inverse inertia Lambda^-1 (robot_inverse_inertia).
  Value value(const Matrix6& Linv) {
    forces(Linv);
    select_tail();
    Value v;
    for (std::size_t j = 0; j < tail_; ++j) v.cvar95 += F_[order_[j]];
    v.cvar95 /= static_cast<double>(tail_);
    // nearest rank 95: the ceil(0.95 N)-th smallest is the (N - ceil(0.95 N) + 1)-th largest
    const std::size_t n = samples_.size(), from_top = n - (95 * n + 99) / 100;  // 0-based among the largest
    std::nth_element(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(from_top), order_.end(),
                     [&](std::size_t a, std::size_t b) { return F_[a] > F_[b]; });
    v.p95 = F_[order_[from_top]];
    return v;
  }

  /// CVaR_95 at (base, theta) and its gradient in theta (size n), free joints. Runs crba; writes data.
  double value_and_gradient(const Model& model, Data& data, const BasePose& base,
                            const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                            Eigen::Ref<Eigen::VectorXd> grad) {
    return value_and_gradient(model, data, base, theta, frame, ContactJoints{}, grad);
  }

  /// The same under the joint model of the contact: Lambda^-1 and its form gradients of that model
  /// (inverse_inertia_matrix and inverse_inertia_form_gradient of effective_mass_gradient.hpp).
  double value_and_gradient(const Model& model, Data& data, const BasePose& base,
                            const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                            const ContactJoints& joints, Eigen::Ref<Eigen::VectorXd> grad) {
    const int n = model.n();
    detail::require_size(grad.size(), n, "RobustForceObjective", "grad");
    g_.resize(n);
    crba(model, data, base, theta);
    forces(inverse_inertia_matrix(model, data, frame, joints));
    select_tail();
    double cvar = 0;
    Matrix6 W = Matrix6::Zero();
    for (std::size_t j = 0; j < tail_; ++j) {
      const std::size_t i = order_[j];
      cvar += F_[i];
      const Vector6& s = samples_[i].wrench;
      W.noalias() += (-p_[i] * F_[i] * M_[i]) * (s * s.transpose());
    }
    cvar /= static_cast<double>(tail_);
    W /= static_cast<double>(tail_);
    const Eigen::SelfAdjointEigenSolver<Matrix6> es(W);
    const double scale = es.eigenvalues().cwiseAbs().maxCoeff();
    grad.setZero();
    for (int k = 0; k < 6; ++k) {
      const double l = es.eigenvalues()(k);
      if (!(std::abs(l) > 1e-15 * scale)) continue;  // rank-deficient W (no contact-point: rank <= 3)
      // data.L is the factor from inverse_inertia_matrix above: not factorized again
      detail::inverse_inertia_form_gradient_prepared(model, data, frame, es.eigenvectors().col(k), joints,
                                                     g_);
      grad += l * g_;
    }
    return cvar;
  }

 private:
  void forces(const Matrix6& Linv) {
    for (std::size_t i = 0; i < samples_.size(); ++i) {
      const Vector6& s = samples_[i].wrench;
      M_[i] = 1.0 / (s.dot(Linv * s) + samples_[i].target_inverse_mass);
      F_[i] = c_[i] * std::pow(M_[i], p_[i]);
      if (!std::isfinite(F_[i]) || !(M_[i] > 0))
        FFSR_THROW(NumericalError(detail::str("RobustForceObjective: sample ", samples_[i].index,
                                         " has no finite force (M_ie = ", M_[i], " kg)")));
    }
  }
  /// order_[0..tail_) = the indices of the tail_ largest forces (ties by index, so deterministic).
  void select_tail() {
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = i;
    // cppcheck-suppress arrayIndexThenCheck ; a < b breaks ties between two valid indices, no bounds check
    auto larger = [&](std::size_t a, std::size_t b) { return F_[a] > F_[b] || (F_[a] == F_[b] && a < b); };
    std::nth_element(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(tail_ - 1), order_.end(),
                     larger);
    std::sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(tail_), larger);
  }

  std::vector<UncertainSample> samples_;
  std::string law_;
  std::vector<double> c_, p_, F_, M_;
  std::vector<std::size_t> order_;
  std::size_t tail_ = 1;
  Eigen::VectorXd g_;
};

}  // namespace ffsr
